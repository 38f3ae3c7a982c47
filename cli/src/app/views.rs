//! `render --views POSES.json`: one scene from many camera poses (a dataset), the shadow maps
//! shared across the batch, each view's outputs written under the `-o` pattern.

use anyhow::{bail, Context as _};
use glam::{Mat4, Vec3};
use serde_json::Value;
use std::path::{Path, PathBuf};
use umbra::render::{AovSet, Aovs, BatchShadows, Renderer};
use umbra::scene::Camera;

/// `render --views`: renders every pose of the file and writes its outputs.
pub fn render_views(a: &super::cli::RenderArgs, poses: &Path) -> anyhow::Result<()> {
    let scene = super::cli::load_scene(a.scene.as_ref(), &a.view)?;
    let view = super::cli::make_view(&scene, &a.view)?;
    let cameras = read_views(poses, &view.camera)?;
    // Every name first, so a bad pattern fails before any rendering.
    let paths = (0..cameras.len() as u32)
        .map(|i| super::cli::frame_path(&a.output, i))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let views: Vec<_> = cameras
        .iter()
        .map(|&camera| umbra::plan::View {
            camera,
            ..view.clone()
        })
        .collect();
    let ctx = crate::offscreen_context(a.validation, a.device.clone())?;
    let mut renderer = Renderer::with_options(&ctx, &scene, &super::cli::scene_options(&a.view))?;
    super::cli::warn_msaa(&a.view, renderer.samples());
    let (w, h) = a.view.size;
    let shadows = if a.per_view_shadows {
        BatchShadows::PerView
    } else {
        BatchShadows::Shared
    };
    let start = std::time::Instant::now();
    let views = match shadows {
        BatchShadows::Shared => renderer.shared_views(&views, w, h),
        BatchShadows::PerView => views,
    };
    // The cache keeps a map the next view plans the same (every view of a shared batch).
    renderer.set_shadow_cache(true);
    let wants = |n: &str| a.outputs.iter().any(|o| o == n);
    let (mut walls, mut drawn) = (Vec::with_capacity(views.len()), 0);
    let mut gpu = Vec::with_capacity(views.len());
    let (aovs, set) = aov_request(&a.outputs);
    if wants("color") {
        // Frames in flight: each view's files are written while the next views are drawn; its
        // camera pass draws the AOVs where it can (one sample a pixel). A view's time is the
        // time between two hand-overs.
        let mut failed = None;
        let mut last = std::time::Instant::now();
        renderer.render_each(&views, w, h, set, &mut |k, f, a| {
            drawn += usize::from(f.stats.casters_drawn > 0);
            gpu.push(f.stats.clone());
            if failed.is_none() {
                failed = write_view(&paths[k], &f.image, a.as_ref(), &aovs).err();
            }
            walls.push(last.elapsed().as_secs_f64() * 1e3);
            last = std::time::Instant::now();
        })?;
        if let Some(e) = failed {
            return Err(e);
        }
    } else if let Some(set) = set {
        walls = render_aovs_only(&mut renderer, (&views, &paths), (w, h), set, &aovs)?;
    }
    let total = start.elapsed().as_secs_f64();
    walls.sort_by(f64::total_cmp);
    let map = views.first().map_or(0, |v| v.shadow.map_size);
    let ms = |f: &dyn Fn(&umbra::FrameStats) -> Option<f64>| {
        crate::median_of(&gpu, f).map_or("n/a".into(), |m| format!("{m:.1} ms"))
    };
    println!(
        "rendered {} views of {} ({}x{}, {}, shadow maps {} at {map}²) on {}: {:.1} ms a view (median {:.1} ms; GPU median shadow {} + camera {}), shadow pass drawn in {drawn} of {} -> {}",
        views.len(), scene.name, w, h, a.outputs.join("+"),
        if a.per_view_shadows { "per view" } else { "shared" }, ctx.device_name,
        total * 1e3 / views.len() as f64, walls[walls.len() / 2],
        ms(&|s| s.gpu_shadow_ms), ms(&|s| s.gpu_camera_ms), views.len(), a.output.display()
    );
    drop(renderer);
    crate::finish_context(ctx)
}

/// The AOVs among `outputs` (in `OUTPUTS` order) and the set to draw them with (`None`: none).
fn aov_request(outputs: &[String]) -> (Vec<&'static &'static str>, Option<AovSet>) {
    let wants = |n: &str| outputs.iter().any(|o| o == n);
    let aovs = OUTPUTS[1..].iter().filter(|n| wants(n)).collect::<Vec<_>>();
    let set = AovSet {
        instance: wants("segmentation"),
        normal: wants("normals"),
        depth: wants("depth"),
    };
    let set = (!aovs.is_empty()).then_some(set);
    (aovs, set)
}

/// Renders the AOVs `names` of every view without colour (the AOV pass) and writes them beside
/// the view's path; returns each view's wall time (ms).
fn render_aovs_only(
    renderer: &mut Renderer,
    (views, paths): (&[umbra::plan::View], &[PathBuf]),
    (w, h): (u32, u32),
    set: AovSet,
    names: &[&&str],
) -> anyhow::Result<Vec<f64>> {
    let mut walls = Vec::with_capacity(views.len());
    for (v, png) in views.iter().zip(paths) {
        let t = std::time::Instant::now();
        let a = renderer.render_aovs_of(v, w, h, set)?;
        for n in names {
            write_aov(&output_path(png, n), n, &a)?;
        }
        walls.push(t.elapsed().as_secs_f64() * 1e3);
    }
    Ok(walls)
}

/// Writes one view's PNG and the AOVs `names` beside it.
fn write_view(
    png: &Path,
    image: &image::RgbaImage,
    a: Option<&Aovs>,
    names: &[&&str],
) -> anyhow::Result<()> {
    image
        .save(png)
        .with_context(|| format!("writing {}", png.display()))?;
    if let Some(a) = a {
        for n in names {
            write_aov(&output_path(png, n), n, a)?;
        }
    }
    Ok(())
}

/// The outputs `--outputs` takes.
pub const OUTPUTS: [&str; 4] = ["color", "depth", "segmentation", "normals"];

/// The cameras of a poses file: `base`'s projection and range at each pose. The file holds a
/// JSON list (or `{"poses": [...]}`) of 4×4 world-from-camera matrices written row by row
/// (the camera looks down its −Z, as numpy poses and glTF nodes), or of
/// `{"eye": [x, y, z], "target": [x, y, z]}`.
pub fn read_views(path: &Path, base: &Camera) -> anyhow::Result<Vec<Camera>> {
    let text = std::fs::read_to_string(path).with_context(|| format!("{}", path.display()))?;
    let json: Value =
        serde_json::from_str(&text).with_context(|| format!("{}: not JSON", path.display()))?;
    let list = match &json {
        Value::Array(a) => a,
        Value::Object(o) => match o.get("poses") {
            Some(Value::Array(a)) => a,
            _ => bail!(
                "{}: expected a list of poses or {{\"poses\": [...]}}",
                path.display()
            ),
        },
        _ => bail!("{}: expected a list of poses", path.display()),
    };
    if list.is_empty() {
        bail!("{}: no poses", path.display());
    }
    list.iter()
        .enumerate()
        .map(|(i, p)| {
            let world_from_view =
                pose(p).with_context(|| format!("{}: pose {i}", path.display()))?;
            Ok(Camera {
                world_from_view,
                ..*base
            })
        })
        .collect()
}

/// World-from-camera of one pose entry.
fn pose(p: &Value) -> anyhow::Result<Mat4> {
    let m = match p {
        Value::Object(o) => {
            let eye = vec3(o.get("eye"), "eye")?;
            let target = vec3(o.get("target"), "target")?;
            if (target - eye).length_squared() <= 0.0 {
                bail!("eye and target are the same point");
            }
            for (p, name) in [(eye, "eye"), (target, "target")] {
                Camera::check_position(p).map_err(|e| anyhow::anyhow!("\"{name}\": {e}"))?;
            }
            Camera::look_at(eye, target, 1.0, 1.0).world_from_view
        }
        Value::Array(rows) => {
            let n: Vec<f32> = rows
                .iter()
                .flat_map(|r| match r {
                    Value::Array(r) => r.iter().collect::<Vec<_>>(),
                    v => vec![v],
                })
                .map(|v| v.as_f64().map(|x| x as f32))
                .collect::<Option<_>>()
                .context("a matrix holds something other than numbers")?;
            if n.len() != 16 {
                bail!(
                    "a matrix of {} numbers, expected 16 (4×4, row by row)",
                    n.len()
                );
            }
            Camera::rigid_pose(Mat4::from_cols_slice(&n).transpose())
                .map_err(|e| anyhow::anyhow!("not a camera pose: {e}"))?
        }
        _ => bail!("expected a 4×4 matrix or {{\"eye\", \"target\"}}"),
    };
    Ok(m)
}

fn vec3(v: Option<&Value>, name: &str) -> anyhow::Result<Vec3> {
    let a: Option<Vec<f32>> = v.and_then(Value::as_array).and_then(|a| {
        a.iter()
            .map(|x| x.as_f64().map(|x| x as f32))
            .collect::<Option<Vec<_>>>()
    });
    match a {
        Some(a) if a.len() == 3 && a.iter().all(|x| x.is_finite()) => Ok(Vec3::from_slice(&a)),
        _ => bail!("\"{name}\": expected three finite numbers"),
    }
}

/// Where output `name` of the image at `png` goes: the image itself for colour, else beside it
/// as `NAME.depth.npy`, `NAME.segmentation.npy` or `NAME.normals.npy`.
pub fn output_path(png: &Path, name: &str) -> PathBuf {
    if name == "color" {
        return png.to_path_buf();
    }
    png.with_extension(format!("{name}.npy"))
}

/// Writes `name` of `aovs` as a `.npy` array: depth float32 (H, W) (distance along the view
/// axis, 0 where nothing), segmentation uint32 (H, W) (instance + 1, 0 where nothing), normals
/// float32 (H, W, 3) (world space).
pub fn write_aov(path: &Path, name: &str, a: &Aovs) -> anyhow::Result<()> {
    let (h, w) = (a.height as usize, a.width as usize);
    let (descr, shape, bytes): (&str, String, Vec<u8>) = match name {
        "depth" => ("<f4", format!("({h}, {w})"), le(&a.depth)),
        "segmentation" => ("<u4", format!("({h}, {w})"), le(&a.instance)),
        "normals" => (
            "<f4",
            format!("({h}, {w}, 3)"),
            le(&a.normal.iter().flatten().copied().collect::<Vec<f32>>()),
        ),
        _ => bail!("unknown output {name}"),
    };
    let mut out = npy_header(descr, &shape);
    out.extend_from_slice(&bytes);
    std::fs::write(path, out).with_context(|| format!("writing {}", path.display()))
}

fn le<T: Copy + Into<LeBytes>>(v: &[T]) -> Vec<u8> {
    v.iter().flat_map(|x| (*x).into().0).collect()
}

/// A 4-byte little-endian value.
pub struct LeBytes([u8; 4]);

impl From<f32> for LeBytes {
    fn from(x: f32) -> Self {
        Self(x.to_le_bytes())
    }
}

impl From<u32> for LeBytes {
    fn from(x: u32) -> Self {
        Self(x.to_le_bytes())
    }
}

/// The header of a version 1.0 `.npy` file (C order), padded so the data starts at a multiple
/// of 64 bytes.
fn npy_header(descr: &str, shape: &str) -> Vec<u8> {
    let mut dict = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
    let unpadded = 10 + dict.len() + 1;
    dict.push_str(&" ".repeat((64 - unpadded % 64) % 64));
    dict.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&(dict.len() as u16).to_le_bytes());
    out.extend_from_slice(dict.as_bytes());
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn npy_header_is_aligned() {
        let h = npy_header("<f4", "(480, 640)");
        assert_eq!(h.len() % 64, 0);
        assert!(h.ends_with(b"\n"));
    }

    #[test]
    fn poses_parse_both_ways() {
        let p: Value = serde_json::from_str("[[1,0,0,2],[0,1,0,3],[0,0,1,4],[0,0,0,1]]").unwrap();
        let m = pose(&p).unwrap();
        assert_eq!(m.w_axis.truncate(), Vec3::new(2.0, 3.0, 4.0));
        let e: Value = serde_json::from_str(r#"{"eye":[0,0,5],"target":[0,0,0]}"#).unwrap();
        let m = pose(&e).unwrap();
        // Looks down −Z from (0, 0, 5).
        assert!((m.transform_vector3(-Vec3::Z) - -Vec3::Z).length() < 1e-6);
        assert!(pose(&serde_json::from_str("[1,2,3]").unwrap()).is_err());
        assert!(
            pose(&serde_json::from_str(r#"{"eye":[0,0,0],"target":[0,0,0]}"#).unwrap()).is_err()
        );
    }
}
