//! `umbra.Scene`: a glTF file or meshes given as arrays, lights, and instance poses.

use crate::arrays::{matrix4, rows, values};
use crate::LoadError;
use glam::{Mat4, Vec3, Vec4};
use pyo3::exceptions::{PyIndexError, PyValueError};
use pyo3::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};
use umbra::scene::built::shapes::{add_object, add_texture, primitive_from_arrays, MeshArrays};
use umbra::scene::{AlphaMode, Light, LightKind, Material, Scene, Texture, TextureRef};

static NEXT_ID: AtomicU64 = AtomicU64::new(1);

/// A scene: meshes, materials, textures, lights and cameras.
#[pyclass(name = "Scene", module = "umbra")]
pub struct PyScene {
    /// The engine scene.
    pub scene: Scene,
    /// Identifies this scene for a renderer's upload cache.
    pub id: u64,
    /// Bumped when meshes, materials or lights are added (a renderer uploads it again).
    pub geometry: u64,
    /// Bumped when an instance moves or the scene is posed (a renderer updates its draws).
    pub poses: u64,
}

impl PyScene {
    fn of(scene: Scene) -> Self {
        Self {
            scene,
            id: NEXT_ID.fetch_add(1, Ordering::Relaxed),
            geometry: 0,
            poses: 0,
        }
    }

    /// Loads a glTF file (`umbra.load`).
    pub fn load(path: std::path::PathBuf) -> PyResult<Self> {
        umbra::load_gltf(&path)
            .map(Self::of)
            .map_err(|e| LoadError::new_err(e.to_string()))
    }

    fn add_light(&mut self, l: Light) -> usize {
        self.scene.lights.push(l);
        self.geometry += 1;
        self.scene.lights.len() - 1
    }
}

/// A colour of 3 or 4 components.
fn rgba(c: &[f32]) -> PyResult<Vec4> {
    match c {
        [r, g, b] => Ok(Vec4::new(*r, *g, *b, 1.0)),
        [r, g, b, a] => Ok(Vec4::new(*r, *g, *b, *a)),
        _ => Err(PyValueError::new_err("a colour has 3 or 4 components")),
    }
}

fn vec3(v: [f32; 3], name: &str) -> PyResult<Vec3> {
    let v = Vec3::from_array(v);
    if v.is_finite() {
        Ok(v)
    } else {
        Err(PyValueError::new_err(format!("{name} must be finite")))
    }
}

fn intensity(i: f32) -> PyResult<f32> {
    if i.is_finite() && i >= 0.0 {
        Ok(i)
    } else {
        Err(PyValueError::new_err(format!("intensity {i} must be >= 0")))
    }
}

#[pymethods]
impl PyScene {
    /// An empty scene (add meshes and lights to it).
    #[new]
    fn new() -> Self {
        Self::of(Scene {
            name: "scene".into(),
            ..Default::default()
        })
    }

    /// Loads a glTF 2.0 file; raises `LoadError` when it cannot.
    #[staticmethod]
    #[pyo3(name = "load")]
    fn load_py(path: std::path::PathBuf) -> PyResult<Self> {
        Self::load(path)
    }

    /// A scene of a `trimesh.Trimesh` or `trimesh.Scene` (its meshes, vertex colours, face
    /// normals as stored, node transforms).
    #[staticmethod]
    fn from_trimesh(obj: &Bound<'_, PyAny>) -> PyResult<Self> {
        let py = obj.py();
        let parts = py
            .import("umbra._trimesh")?
            .call_method1("to_arrays", (obj,))?;
        let mut s = Self::new();
        for part in parts.try_iter()? {
            let p = part?;
            let get = |k: &str| p.get_item(k);
            s.add_mesh(
                &get("positions")?,
                Some(&get("indices")?).filter(|v| !v.is_none()),
                Some(&get("normals")?).filter(|v| !v.is_none()),
                Some(&get("uvs")?).filter(|v| !v.is_none()),
                Some(&get("colors")?).filter(|v| !v.is_none()),
                get("base_color")?.extract()?,
                Some(&get("pose")?),
                get("name")?.extract()?,
                0.0,
                0.6,
                true,
                false,
                &get("alpha_mode")?.extract::<String>()?,
                0.5,
                Some(&get("texture")?),
            )?;
        }
        Ok(s)
    }

    /// Adds a triangle mesh and one instance of it; returns the instance index (what
    /// `segmentation` reports, plus 1). `positions` float32 (N, 3); `indices` uint32 (M, 3) or
    /// None (every three positions a triangle); `normals` (N, 3) (smooth normals are computed
    /// without); `uvs` (N, 2); `colors` (N, 3) or (N, 4) linear values within 0..1 (uint8: /255)
    /// multiplying `base_color` (linear RGBA); `texture` uint8 (H, W, 3|4) sRGB base-colour
    /// image read at `uvs`; `pose` 4×4 world-from-model. `alpha_mode` as glTF's: "OPAQUE" (alpha
    /// ignored), "MASK" (cut out below `alpha_cutoff`) or "BLEND".
    #[pyo3(signature = (positions, indices = None, normals = None, uvs = None, colors = None,
        base_color = vec![1.0, 1.0, 1.0, 1.0], pose = None, name = None, metallic = 0.0,
        roughness = 0.6, double_sided = false, unlit = false, alpha_mode = "OPAQUE",
        alpha_cutoff = 0.5, texture = None))]
    #[allow(clippy::too_many_arguments)] // Python keyword arguments
    fn add_mesh(
        &mut self,
        positions: &Bound<'_, PyAny>,
        indices: Option<&Bound<'_, PyAny>>,
        normals: Option<&Bound<'_, PyAny>>,
        uvs: Option<&Bound<'_, PyAny>>,
        colors: Option<&Bound<'_, PyAny>>,
        base_color: Vec<f32>,
        pose: Option<&Bound<'_, PyAny>>,
        name: Option<String>,
        metallic: f32,
        roughness: f32,
        double_sided: bool,
        unlit: bool,
        alpha_mode: &str,
        alpha_cutoff: f32,
        texture: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<usize> {
        let alpha_mode = match alpha_mode.to_ascii_uppercase().as_str() {
            "OPAQUE" => AlphaMode::Opaque,
            "MASK" if alpha_cutoff.is_finite() => AlphaMode::Mask(alpha_cutoff),
            "BLEND" => AlphaMode::Blend,
            "MASK" => return Err(PyValueError::new_err("alpha_cutoff must be finite")),
            other => {
                return Err(PyValueError::new_err(format!(
                    "alpha_mode '{other}' is not OPAQUE, MASK or BLEND"
                )))
            }
        };
        let positions = rows::<3>(positions, "positions")?;
        let indices = match indices {
            Some(i) => Some(values::<u32>(i, "uint32", "indices")?.0),
            None => None,
        };
        let normals = normals.map(|n| rows::<3>(n, "normals")).transpose()?;
        let uvs = uvs.map(|u| rows::<2>(u, "uvs")).transpose()?;
        let colors = colors.map(read_colors).transpose()?;
        let texture = match texture {
            Some(t) if !t.is_none() => {
                if uvs.is_none() {
                    return Err(PyValueError::new_err("texture: needs uvs"));
                }
                Some(read_texture(t, name.as_deref().unwrap_or("texture"))?)
            }
            _ => None,
        };
        let prim = primitive_from_arrays(&MeshArrays {
            positions: &positions,
            indices: indices.as_deref(),
            normals: normals.as_deref(),
            uvs: uvs.as_deref(),
            colors: colors.as_deref(),
        })
        .map_err(|e| PyValueError::new_err(format!("add_mesh: {e}")))?;
        let world_from_model = match pose {
            Some(p) if !p.is_none() => matrix4(p, "pose")?,
            _ => Mat4::IDENTITY,
        };
        let base_color_texture = texture.map(|t| TextureRef::new(add_texture(&mut self.scene, t)));
        let material = Material {
            name: name.clone().unwrap_or_else(|| "mesh".into()),
            base_color_texture,
            base_color: rgba(&base_color)?,
            metallic: metallic.clamp(0.0, 1.0),
            roughness: roughness.clamp(0.0, 1.0),
            double_sided,
            unlit,
            alpha_mode,
            ..Default::default()
        };
        let n = self.scene.instances.len();
        let name = name.unwrap_or_else(|| format!("mesh {n}"));
        add_object(&mut self.scene, &name, prim, material, world_from_model);
        self.geometry += 1;
        Ok(n)
    }

    /// Adds a sun travelling along `direction` (a glTF light shines down its −Z); returns the
    /// light's index.
    #[pyo3(signature = (direction, intensity = 1.0, color = (1.0, 1.0, 1.0), shadows = true))]
    fn add_directional_light(
        &mut self,
        direction: [f32; 3],
        intensity: f32,
        color: (f32, f32, f32),
        shadows: bool,
    ) -> PyResult<usize> {
        let d = vec3(direction, "direction")?;
        if d.length_squared() == 0.0 {
            return Err(PyValueError::new_err("direction must not be zero"));
        }
        let mut l = Light::sun(d, self::intensity(intensity)?);
        l.color = Vec3::from(color);
        l.casts_shadows = shadows;
        Ok(self.add_light(l))
    }

    /// Adds a point light at `position` (`intensity` in candela; `range`: zero beyond).
    #[pyo3(signature = (position, intensity = 1.0, color = (1.0, 1.0, 1.0), range = None,
        shadows = true))]
    fn add_point_light(
        &mut self,
        position: [f32; 3],
        intensity: f32,
        color: (f32, f32, f32),
        range: Option<f32>,
        shadows: bool,
    ) -> PyResult<usize> {
        let l = Light {
            kind: LightKind::Point,
            position: vec3(position, "position")?,
            color: Vec3::from(color),
            intensity: self::intensity(intensity)?,
            casts_shadows: shadows,
            range,
            ..Light::sun(Vec3::NEG_Y, 1.0)
        };
        Ok(self.add_light(l))
    }

    /// Adds a spot light at `position` shining along `direction`, full inside `inner_cone` and
    /// dark outside `outer_cone` (half-angles, radians).
    #[pyo3(signature = (position, direction, inner_cone = 0.0,
        outer_cone = std::f32::consts::FRAC_PI_4, intensity = 1.0, color = (1.0, 1.0, 1.0),
        range = None, shadows = true))]
    #[allow(clippy::too_many_arguments)] // Python keyword arguments
    fn add_spot_light(
        &mut self,
        position: [f32; 3],
        direction: [f32; 3],
        inner_cone: f32,
        outer_cone: f32,
        intensity: f32,
        color: (f32, f32, f32),
        range: Option<f32>,
        shadows: bool,
    ) -> PyResult<usize> {
        if !(0.0..std::f32::consts::FRAC_PI_2).contains(&outer_cone) || inner_cone > outer_cone {
            return Err(PyValueError::new_err(
                "cones must satisfy 0 <= inner_cone <= outer_cone < π/2",
            ));
        }
        let l = Light {
            kind: LightKind::Spot {
                inner: inner_cone.max(0.0),
                outer: outer_cone.max(inner_cone.max(0.0) + 1e-4),
            },
            position: vec3(position, "position")?,
            direction: vec3(direction, "direction")?.normalize_or(Vec3::NEG_Y),
            color: Vec3::from(color),
            intensity: self::intensity(intensity)?,
            casts_shadows: shadows,
            range,
            size: 0.0,
        };
        Ok(self.add_light(l))
    }

    /// Moves instance `instance` to `pose` (4×4 world-from-model).
    fn set_pose(&mut self, instance: usize, pose: &Bound<'_, PyAny>) -> PyResult<()> {
        let m = matrix4(pose, "pose")?;
        let n = self.scene.instances.len();
        let i = self
            .scene
            .instances
            .get_mut(instance)
            .ok_or_else(|| PyIndexError::new_err(format!("instance {instance} of {n}")))?;
        i.world_from_model = m;
        self.poses += 1;
        Ok(())
    }

    /// Adds a grey ground plane under the scene, wide enough for its shadows (the command line's
    /// `--ground`); returns its instance index. Raises ValueError on a scene without geometry,
    /// which gives the ground no size.
    fn add_ground(&mut self) -> PyResult<usize> {
        let before = self.scene.instances.len();
        umbra::scene::built::shapes::add_ground(&mut self.scene);
        if self.scene.instances.len() == before {
            return Err(PyValueError::new_err(
                "add_ground: the scene has no geometry to size the ground by; add meshes first",
            ));
        }
        self.geometry += 1;
        Ok(before)
    }

    /// The camera (and its 4×4 pose) umbra frames this scene with at `width`×`height`: the
    /// file's first camera, else the front view (`umbra render` without a camera).
    fn default_view<'py>(
        &self,
        py: Python<'py>,
        width: u32,
        height: u32,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let aspect = width as f32 / height.max(1) as f32;
        let c = self
            .scene
            .cameras
            .first()
            .copied()
            .unwrap_or_else(|| self.scene.default_camera(aspect));
        crate::camera::python_camera(py, &c)
    }

    /// The file's cameras (node order), each as (camera, pose).
    #[getter]
    fn cameras<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<Vec<(Bound<'py, PyAny>, Bound<'py, PyAny>)>> {
        self.scene
            .cameras
            .iter()
            .map(|c| crate::camera::python_camera(py, c))
            .collect()
    }

    /// Its name (the file's name for a loaded scene).
    #[getter]
    fn name(&self) -> String {
        self.scene.name.clone()
    }

    /// Instances (placed meshes).
    #[getter]
    fn instances(&self) -> usize {
        self.scene.instances.len()
    }

    /// Lights.
    #[getter]
    fn lights(&self) -> usize {
        self.scene.lights.len()
    }

    /// Triangles drawn.
    #[getter]
    fn triangles(&self) -> usize {
        self.scene.triangle_count()
    }

    /// World bounds: ((min x, y, z), (max x, y, z)).
    #[getter]
    fn bounds(&self) -> ([f32; 3], [f32; 3]) {
        let b = self.scene.bounds();
        (b.min.to_array(), b.max.to_array())
    }

    /// The loader's findings: one line each, with its code (as the command line prints them).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.scene
            .warnings
            .iter()
            .map(|w| format!("{} [{} {}]", w.message, w.code, w.pointer))
            .collect()
    }

    /// The names of its animations.
    #[getter]
    fn animations(&self) -> Vec<String> {
        self.scene
            .rig
            .as_ref()
            .map(|r| r.animations.iter().map(|a| a.name.clone()).collect())
            .unwrap_or_default()
    }

    fn __repr__(&self) -> String {
        format!(
            "Scene('{}', {} instances, {} triangles, {} lights)",
            self.scene.name,
            self.scene.instances.len(),
            self.scene.triangle_count(),
            self.scene.lights.len()
        )
    }
}

/// Vertex colours: (N, 3) or (N, 4), floats within 0..1 or uint8 (/255).
/// An sRGB uint8 (H, W, 3|4) image as a texture.
fn read_texture(t: &Bound<'_, PyAny>, name: &str) -> PyResult<Texture> {
    let (width, height, rgba) = crate::arrays::rgba8(t, "texture")?;
    Ok(Texture {
        name: name.to_string(),
        width,
        height,
        rgba,
        ktx2: None,
    })
}

fn read_colors(c: &Bound<'_, PyAny>) -> PyResult<Vec<[f32; 4]>> {
    let dtype: String = c
        .getattr("dtype")
        .and_then(|d| d.str())
        .map(|s| s.to_string())
        .unwrap_or_default();
    let scale = if dtype == "uint8" { 1.0 / 255.0 } else { 1.0 };
    let (v, shape) = values::<f32>(c, "float32", "colors")?;
    let k = match shape.as_slice() {
        [_, k @ (3 | 4)] => *k,
        _ => {
            return Err(PyValueError::new_err(format!(
                "colors: shape {shape:?}, expected (n, 3) or (n, 4)"
            )))
        }
    };
    Ok(v.chunks_exact(k)
        .map(|c| {
            let a = if k == 4 { c[3] * scale } else { 1.0 };
            [c[0] * scale, c[1] * scale, c[2] * scale, a]
        })
        .collect())
}
