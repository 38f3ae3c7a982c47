//! `umbra.OffscreenRenderer`: pyrender's offscreen renderer, shaped the same (`render(scene,
//! camera, camera_pose)` → colour and depth), with more outputs and umbra's shadow settings. A
//! scene is uploaded once and kept while it only moves; the GIL is released while the GPU works.

use crate::arrays::{check_room, image_out, matrix4, values};
use crate::camera::{camera_pose, engine_camera};
use crate::scene::PyScene;
use crate::settings::{self, Extras};
use crate::{gpu_error, UmbraError};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use std::sync::Arc;
use umbra::plan::{SceneOptions, View, ViewMode};
use umbra::render::Renderer;
use umbra::scene::anim::Playing;
use umbra::{Context, ContextDesc, Validation};

/// What `render` can return.
const OUTPUTS: [&str; 5] = ["color", "depth", "segmentation", "normals", "shadow"];

/// A scene's upload, kept for the frames that follow.
struct Cached {
    scene: u64,
    geometry: u64,
    poses: u64,
    renderer: Renderer,
}

/// Renders scenes offscreen into numpy arrays.
#[pyclass(module = "umbra")]
pub struct OffscreenRenderer {
    width: u32,
    height: u32,
    options: SceneOptions,
    // Dropped before the context.
    cached: Option<Cached>,
    ctx: Option<Arc<Context>>,
}

/// An output's values.
enum Data {
    /// A lit image, RGBA8: its RGB is what the array holds (converted where it is stacked).
    Rgba(Vec<u8>),
    U8(Vec<u8>),
    F32(Vec<f32>),
    U32(Vec<u32>),
}

struct Output {
    name: &'static str,
    data: Data,
    channels: usize,
}

impl OffscreenRenderer {
    fn ctx(&self) -> PyResult<Arc<Context>> {
        self.ctx
            .clone()
            .ok_or_else(|| UmbraError::new_err("this renderer was closed"))
    }

    /// The renderer for `scene`, uploaded again only when meshes or lights were added, posed
    /// again when instances moved.
    fn renderer_for(&mut self, scene: &PyScene) -> PyResult<&mut Renderer> {
        let ctx = self.ctx()?;
        let keep = self
            .cached
            .as_ref()
            .is_some_and(|c| c.scene == scene.id && c.geometry == scene.geometry);
        if !keep {
            self.cached = None;
            let renderer =
                Renderer::with_options(&ctx, &scene.scene, &self.options).map_err(gpu_error)?;
            self.cached = Some(Cached {
                scene: scene.id,
                geometry: scene.geometry,
                poses: scene.poses,
                renderer,
            });
        }
        let c = self.cached.as_mut().expect("made above");
        if c.poses != scene.poses {
            c.renderer.set_pose(&scene.scene).map_err(gpu_error)?;
            c.poses = scene.poses;
        }
        Ok(&mut c.renderer)
    }

    /// Poses `scene` at the settings' time (`time`, `animation`).
    fn pose(scene: &mut PyScene, extras: &Extras) -> PyResult<()> {
        let Some(t) = extras.time else {
            if extras.animation.is_some() {
                return Err(PyValueError::new_err("animation needs a time"));
            }
            return Ok(());
        };
        let rig = scene.scene.rig.clone();
        let playing = match &extras.animation {
            Some(spec) => Playing::parse(spec, rig.as_deref())
                .map_err(|e| PyValueError::new_err(format!("animation: {e}")))?,
            None => Playing::first(rig.as_deref()),
        };
        scene.scene.pose_at(&playing, t);
        scene.poses += 1;
        Ok(())
    }

    /// Renders `scene` through `camera` from each of `poses` with `settings`, the `outputs`
    /// stacked (`stacked`: with a leading frame axis).
    /// `shared`: the poses' shadow maps fitted to them all and drawn once
    /// (`BatchShadows::Shared`; not with a budget, which chooses per frame).
    #[allow(clippy::too_many_arguments)] // the Python call's arguments, passed on
    fn render_poses<'py>(
        &mut self,
        py: Python<'py>,
        scene: &Bound<'py, PyScene>,
        camera: &Bound<'py, PyAny>,
        poses: &[glam::Mat4],
        outputs: &[&'static str],
        settings: Option<&Bound<'py, PyDict>>,
        (stacked, shared): (bool, bool),
    ) -> PyResult<Bound<'py, PyDict>> {
        let aspect = self.width as f32 / self.height as f32;
        let mut base = View::new(engine_camera(camera, poses[0], aspect)?);
        let extras = settings::apply(&mut base, settings)?;
        let mut s = scene.borrow_mut();
        Self::pose(&mut s, &extras)?;
        let mut views = Vec::with_capacity(poses.len());
        for &pose in poses {
            let mut view = base.clone();
            view.camera = engine_camera(camera, pose, aspect)?;
            views.push(view);
        }
        if shared && extras.budget.is_none() {
            let (w, h) = (self.width, self.height);
            views = self.renderer_for(&s)?.shared_views(&views, w, h);
        }
        // A batch keeps a map the next pose plans the same (every pose of a shared batch).
        let cache = stacked || self.options.shadow_cache;
        self.renderer_for(&s)?.set_shadow_cache(cache);
        let mut stack = Stack::new(poses.len());
        if extras.budget.is_none() && outputs.contains(&"color") && !outputs.contains(&"shadow") {
            // One call for the poses, the next drawn while the last is read back and converted.
            let (w, h) = (self.width, self.height);
            let set = aov_set(outputs);
            let renderer = self.renderer_for(&s)?;
            py.detach(|| {
                renderer.render_each(&views, w, h, set, &mut |_, f, a| {
                    stack.push(outputs_of(Some(f), a, set))
                })
            })
            .map_err(gpu_error)?;
        } else {
            for view in &views {
                stack.push(self.frame(py, &s, view, &extras, outputs)?);
            }
        }
        stack.into_arrays(py, (self.width, self.height), stacked)
    }

    /// Renders `view` of `scene` into the `outputs` asked for.
    fn frame(
        &mut self,
        py: Python<'_>,
        scene: &PyScene,
        view: &View,
        extras: &Extras,
        outputs: &[&'static str],
    ) -> PyResult<Vec<Output>> {
        let (w, h) = (self.width, self.height);
        let renderer = self.renderer_for(scene)?;
        let mut view = view.clone();
        if let Some(b) = extras.budget {
            choose_budget(renderer, &scene.scene, &mut view, (w, h), b)?;
        }
        // The GPU's work, without the GIL.
        py.detach(|| render_outputs(renderer, &view, (w, h), outputs))
            .map_err(gpu_error)
    }
}

/// Sets `view`'s shadow settings to the cheapest within `budget` (`analysis::budget::choose`).
fn choose_budget(
    renderer: &mut Renderer,
    scene: &umbra::Scene,
    view: &mut View,
    size: (u32, u32),
    budget: f64,
) -> PyResult<()> {
    let reference = umbra_lab::reference::ReferenceScene::new(scene);
    let c =
        umbra_lab::analysis::budget::choose(renderer, &reference, scene, view, size, budget, None)
            .map_err(gpu_error)?;
    if let Some(c) = c {
        view.shadow = c.chosen.config.shadow;
    }
    Ok(())
}

/// The AOVs `outputs` asks for (None: none).
fn aov_set(outputs: &[&'static str]) -> Option<umbra::render::AovSet> {
    let set = umbra::render::AovSet {
        instance: outputs.contains(&"segmentation"),
        normal: outputs.contains(&"normals"),
        depth: outputs.contains(&"depth"),
    };
    (set.instance || set.normal || set.depth).then_some(set)
}

/// The outputs of a frame (`color`) and its AOVs (those in `set`), in the order of `OUTPUTS`.
fn outputs_of(
    frame: Option<umbra::RenderedFrame>,
    aovs: Option<umbra::render::Aovs>,
    set: Option<umbra::render::AovSet>,
) -> Vec<Output> {
    let mut out = Vec::new();
    if let Some(f) = frame {
        out.push(Output {
            name: "color",
            data: Data::Rgba(f.image.into_raw()),
            channels: 3,
        });
    }
    if let (Some(a), Some(set)) = (aovs, set) {
        if set.depth {
            out.push(Output {
                name: "depth",
                data: Data::F32(a.depth),
                channels: 1,
            });
        }
        if set.instance {
            out.push(Output {
                name: "segmentation",
                data: Data::U32(a.instance),
                channels: 1,
            });
        }
        if set.normal {
            out.push(Output {
                name: "normals",
                data: Data::F32(a.normal.into_flattened()),
                channels: 3,
            });
        }
    }
    out
}

/// The frames `outputs` need: the lit image (with the AOVs drawn by its own camera pass at one
/// sample per pixel: `Renderer::render_with_aovs`), the AOV pass alone, the shadow view.
fn render_outputs(
    r: &mut Renderer,
    view: &View,
    (w, h): (u32, u32),
    outputs: &[&'static str],
) -> Result<Vec<Output>, umbra::GpuError> {
    let wants = |n: &str| outputs.contains(&n);
    let set = aov_set(outputs);
    let mut out = if wants("color") {
        match set {
            Some(s) => {
                let (f, a) = r.render_with_aovs(view, w, h, s)?;
                outputs_of(Some(f), Some(a), set)
            }
            None => outputs_of(Some(r.render(view, w, h)?), None, set),
        }
    } else {
        match set {
            Some(s) => outputs_of(None, Some(r.render_aovs_of(view, w, h, s)?), set),
            None => Vec::new(),
        }
    };
    if wants("shadow") {
        let mut v = view.clone();
        v.mode = ViewMode::Shadow;
        let f = r.render(&v, w, h)?;
        out.push(Output {
            name: "shadow",
            data: Data::F32(f.image.pixels().map(|p| p[0] as f32 / 255.0).collect()),
            channels: 1,
        });
    }
    Ok(out)
}

/// The outputs asked for, checked, in `OUTPUTS` order.
fn parse_outputs(outputs: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<&'static str>> {
    let Some(o) = outputs else {
        return Ok(vec!["color", "depth"]);
    };
    let names: Vec<String> = if let Ok(s) = o.extract::<String>() {
        vec![s]
    } else {
        o.extract()?
    };
    for n in &names {
        if !OUTPUTS.contains(&n.as_str()) {
            return Err(PyValueError::new_err(format!(
                "unknown output '{n}' (one of {})",
                OUTPUTS.join(", ")
            )));
        }
    }
    Ok(OUTPUTS
        .into_iter()
        .filter(|o| names.iter().any(|n| n == o))
        .collect())
}

/// Appends RGBA8 pixels without their alpha to `rgb`, a pixel at a time in place (an iterator of
/// per-pixel arrays collected into a new vector took 3 ms a 640×480 frame on lavapipe's host, a
/// tenth of a batched FlightHelmet view).
fn append_rgb(rgb: &mut Vec<u8>, rgba: &[u8]) {
    let start = rgb.len();
    rgb.resize(start + rgba.len() / 4 * 3, 0);
    for (d, s) in rgb[start..].chunks_exact_mut(3).zip(rgba.chunks_exact(4)) {
        d.copy_from_slice(&s[..3]);
    }
}

/// Outputs of one or more frames, each output's values one frame after another.
struct Stack {
    frames: usize,
    /// Frames expected (room is made for them at the first).
    expected: usize,
    outputs: Vec<Output>,
}

impl Stack {
    fn new(expected: usize) -> Self {
        Self {
            frames: 0,
            expected,
            outputs: Vec::new(),
        }
    }

    /// Appends one frame's outputs (in the order of the first frame's).
    fn push(&mut self, frame: Vec<Output>) {
        if self.frames == 0 {
            let more = self.expected.saturating_sub(1);
            self.outputs = frame;
            for o in &mut self.outputs {
                match &mut o.data {
                    Data::Rgba(v) => {
                        let mut rgb = Vec::with_capacity(v.len() / 4 * 3 * self.expected);
                        append_rgb(&mut rgb, v);
                        o.data = Data::U8(rgb);
                    }
                    Data::U8(v) => v.reserve_exact(v.len() * more),
                    Data::F32(v) => v.reserve_exact(v.len() * more),
                    Data::U32(v) => v.reserve_exact(v.len() * more),
                }
            }
        } else {
            for (acc, o) in self.outputs.iter_mut().zip(frame) {
                match (&mut acc.data, o.data) {
                    (Data::U8(a), Data::Rgba(b)) => append_rgb(a, &b),
                    (Data::U8(a), Data::U8(b)) => a.extend(b),
                    (Data::F32(a), Data::F32(b)) => a.extend(b),
                    (Data::U32(a), Data::U32(b)) => a.extend(b),
                    _ => unreachable!("an output keeps its type across frames"),
                }
            }
        }
        self.frames += 1;
    }

    /// The outputs as arrays (h, w[, c]), or with `stacked` (frames, h, w[, c]).
    fn into_arrays<'py>(
        self,
        py: Python<'py>,
        (w, h): (u32, u32),
        stacked: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        let frames = stacked.then_some(self.frames);
        for o in self.outputs {
            let array = match o.data {
                Data::U8(v) => image_out(py, v, (w, h), o.channels, frames),
                Data::Rgba(v) => {
                    let mut rgb = Vec::new();
                    append_rgb(&mut rgb, &v);
                    image_out(py, rgb, (w, h), o.channels, frames)
                }
                Data::F32(v) => image_out(py, v, (w, h), o.channels, frames),
                Data::U32(v) => image_out(py, v, (w, h), o.channels, frames),
            };
            d.set_item(o.name, array)?;
        }
        Ok(d)
    }
}

#[pymethods]
impl OffscreenRenderer {
    /// A renderer of `width`×`height` images on `device` (a substring of its name; None: the
    /// `UMBRA_DEVICE` variable, else a GPU before a CPU device), with `msaa` samples a pixel
    /// (None: 4 on GPUs, 1 on CPU devices); `validation` turns the Khronos layer on.
    #[new]
    #[pyo3(signature = (width, height, device = None, msaa = None, validation = false))]
    fn new(
        width: u32,
        height: u32,
        device: Option<String>,
        msaa: Option<u32>,
        validation: bool,
    ) -> PyResult<Self> {
        let max = umbra::render::MAX_SIDE;
        if !(1..=max).contains(&width) || !(1..=max).contains(&height) {
            return Err(PyValueError::new_err(format!(
                "image size {width}x{height} is outside 1x1..{max}x{max}"
            )));
        }
        if let Some(m) = msaa.filter(|m| ![1, 2, 4, 8].contains(m)) {
            return Err(PyValueError::new_err(format!(
                "msaa {m} is not 1, 2, 4 or 8"
            )));
        }
        let ctx = Context::new(&ContextDesc {
            validation: Validation::required_if(validation),
            device,
            ..Default::default()
        })
        .map_err(gpu_error)?;
        Ok(Self {
            width,
            height,
            options: SceneOptions {
                msaa,
                ..Default::default()
            },
            cached: None,
            ctx: Some(ctx),
        })
    }

    /// Renders `scene` through `camera` placed at `camera_pose` (4×4 world-from-camera; the
    /// camera looks down its −Z). Without `outputs`: `(color, depth)`, uint8 (H, W, 3) sRGB and
    /// float32 (H, W) distance along the view axis (0 where nothing is hit). With `outputs` (any
    /// of color, depth, segmentation, normals, shadow): a dict of those arrays
    /// (`segmentation` uint32 (H, W), instance + 1, 0 for the background; `normals` float32
    /// (H, W, 3) world space; `shadow` float32 (H, W), the first shadowed light's visibility, or
    /// `shadow_light`'s). Keyword settings as the command line's options: `shadows`,
    /// `shadow_map`, `shadow_format`, `shadow_method`, `contact_shadows`, `pcf`, `cascades`,
    /// `depth_fit`, `fit`, `bias_constant`, `bias_slope`, `normal_offset`, `shadow_budget` (%),
    /// `shadow_light`, `light_size`,
    /// `exposure`, `tonemap`, `post_aa`, `ambient`, `background`, `sun_direction`,
    /// `sun_intensity`, `time`, `animation`.
    #[pyo3(signature = (scene, camera, camera_pose, outputs = None, **settings))]
    fn render<'py>(
        &mut self,
        py: Python<'py>,
        scene: &Bound<'py, PyScene>,
        camera: &Bound<'py, PyAny>,
        camera_pose: &Bound<'py, PyAny>,
        outputs: Option<&Bound<'py, PyAny>>,
        settings: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let names = parse_outputs(outputs)?;
        let pose = crate::camera::camera_pose(matrix4(camera_pose, "camera_pose")?, "camera_pose")?;
        let d = self.render_poses(py, scene, camera, &[pose], &names, settings, (false, false))?;
        if outputs.is_none() {
            let t = PyTuple::new(py, [d.get_item("color")?, d.get_item("depth")?])?;
            return Ok(t.into_any());
        }
        Ok(d.into_any())
    }

    /// Renders `scene` from each of `poses` (an (N, 4, 4) array of camera poses) without
    /// uploading it again: a dict of the `outputs` (default color and depth), each stacked
    /// (N, H, W[, C]). Settings as `render`. `share_shadows` (the default): each directional
    /// light gets one map fitted to all the poses, as fine as the finest any pose's own fit
    /// would be (its side doubled up to 8192), drawn once for the batch; False: each pose
    /// fitted alone, as `render` fits it.
    #[pyo3(signature = (scene, camera, poses, outputs = None, share_shadows = true, **settings))]
    #[allow(clippy::too_many_arguments)] // the Python call's arguments
    fn render_batch<'py>(
        &mut self,
        py: Python<'py>,
        scene: &Bound<'py, PyScene>,
        camera: &Bound<'py, PyAny>,
        poses: &Bound<'py, PyAny>,
        outputs: Option<&Bound<'py, PyAny>>,
        share_shadows: bool,
        settings: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let names = parse_outputs(outputs)?;
        let (m, shape) = values::<f32>(poses, "float32", "poses")?;
        if shape.len() != 3 || shape[1..] != [4, 4] || shape[0] == 0 {
            return Err(PyValueError::new_err(format!(
                "poses: shape {shape:?}, expected (n, 4, 4) with n ≥ 1"
            )));
        }
        check_room(&names, (self.width, self.height), shape[0])?;
        let list = m
            .chunks_exact(16)
            .enumerate()
            .map(|(i, rows)| {
                let pose = glam::Mat4::from_cols_slice(rows).transpose();
                camera_pose(pose, &format!("poses[{i}]"))
            })
            .collect::<PyResult<Vec<_>>>()?;
        self.render_poses(
            py,
            scene,
            camera,
            &list,
            &names,
            settings,
            (true, share_shadows),
        )
    }

    /// Frees the device's resources (the renderer cannot render afterwards).
    fn close(&mut self) {
        self.cached = None;
        self.ctx = None;
    }

    fn __enter__(slf: Py<Self>) -> Py<Self> {
        slf
    }

    fn __exit__(
        &mut self,
        _exc_type: Option<&Bound<'_, PyAny>>,
        _exc: Option<&Bound<'_, PyAny>>,
        _tb: Option<&Bound<'_, PyAny>>,
    ) {
        self.close();
    }

    /// Image width.
    #[getter]
    fn width(&self) -> u32 {
        self.width
    }

    /// Image height.
    #[getter]
    fn height(&self) -> u32 {
        self.height
    }

    /// The Vulkan device's name.
    #[getter]
    fn device(&self) -> PyResult<String> {
        Ok(self.ctx()?.device_name.clone())
    }

    /// The device class whose golden images this renderer's frames are compared with
    /// (`lavapipe`, `nvidia`, `amd`, `intel`, …; `umbra.testing`).
    #[getter]
    fn device_class(&self) -> PyResult<String> {
        let ctx = self.ctx()?;
        Ok(umbra::golden::device_class(&ctx))
    }

    /// Samples a pixel of the colour image on this device (`msaa` resolved).
    #[getter]
    fn samples(&self) -> PyResult<u32> {
        Ok(self
            .options
            .resolved_samples(&umbra::render::device_facts(&*self.ctx()?)))
    }

    /// Validation messages of warning or error severity so far (with `validation=True`).
    #[getter]
    fn validation_problems(&self) -> PyResult<usize> {
        Ok(self.ctx()?.validation_log.problem_count())
    }

    fn __repr__(&self) -> String {
        let device = self
            .ctx
            .as_ref()
            .map_or("closed".to_string(), |c| c.device_name.clone());
        format!(
            "OffscreenRenderer({}x{}, {device})",
            self.width, self.height
        )
    }
}
