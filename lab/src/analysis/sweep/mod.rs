//! Running a grid of shadow configurations on one view: GPU time per pass (median of N
//! timestamped frames), wall time, shadow-map memory, and accuracy against the ray-cast
//! reference. Rows go to CSV (the record a sweep resumes from) and JSON.

mod io;

pub use io::{read_csv, write_json, CsvAppender, SweepIoError};

use super::grid::{format_name, Config};
use crate::reference::{Metrics, ReferenceFrame, ReferenceScene};
use serde::{Deserialize, Serialize};
use std::path::Path;
use umbra::gpu::GpuError;
use umbra::plan::{View, ViewMode};
use umbra::render::{FrameStats, Renderer};
use umbra::scene::Camera;

/// PSNR written for identical images (instead of ∞, which JSON cannot hold).
pub const PSNR_IDENTICAL_DB: f64 = 100.0;

/// One scene × view × configuration. Column names carry their units; fractions are of the
/// judged pixels (`reference::Metrics`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Row {
    /// Scene name.
    pub scene: String,
    /// View name (`grid::sweep_views`).
    pub view: String,
    /// Configuration name (`Config::name`).
    pub config: String,
    /// Fitting method: scene, camera, cascades2, cascades4.
    pub method: String,
    /// Filter: nearest, pcf2x2, pcf3x3, pcf5x5.
    pub filter: String,
    /// Depth format: d16, d32.
    pub format: String,
    /// Bias preset.
    pub bias: String,
    /// Map side in texels.
    pub map_texels: u32,
    /// Shadow views rendered (cascades used).
    pub shadow_views: u32,
    /// Shadow-map memory (MiB): side² × bytes per texel × layers.
    pub shadow_memory_mib: f64,
    /// Median GPU time of the shadow pass (ms).
    pub gpu_shadow_ms: f64,
    /// Median GPU time of the camera pass (ms).
    pub gpu_camera_ms: f64,
    /// Median GPU time of the frame (ms).
    pub gpu_ms: f64,
    /// Median wall time of `Renderer::render` (ms).
    pub wall_ms: f64,
    /// Misclassified fraction of judged pixels.
    pub misclassified: f64,
    /// Wrongly shadowed fraction.
    pub false_shadow: f64,
    /// Wrongly lit fraction.
    pub false_light: f64,
    /// Misclassified fraction within 2 px of an exact shadow edge.
    pub edge_misclassified: f64,
    /// Misclassified fraction elsewhere.
    pub interior_misclassified: f64,
    /// PSNR of the lit image against the reference (dB; `PSNR_IDENTICAL_DB` when identical).
    pub psnr_db: f64,
    /// Mean FLIP error against the reference image.
    pub flip: f64,
    /// Pixels judged.
    pub judged_pixels: u64,
    /// Image width (px).
    pub width_px: u32,
    /// Image height (px).
    pub height_px: u32,
    /// Frames timed.
    pub frames: u32,
    /// Device name.
    pub device: String,
}

impl Row {
    /// The resume key: scene, view, configuration.
    pub fn key(&self) -> (String, String, String) {
        (self.scene.clone(), self.view.clone(), self.config.clone())
    }
}

/// How each configuration is measured.
#[derive(Clone, Debug)]
pub struct SweepOptions {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Frames timed per configuration, in interleaved rounds.
    pub repeat: usize,
    /// Configurations measured together (interleaved); their rows are handed over when the batch
    /// is done, which is what an interrupted sweep keeps.
    pub batch: usize,
    /// Every light's size (`View::light_size`): the reference is then the area light, and
    /// configurations other than PCSS's cast hard shadows from it.
    pub light_size: Option<f32>,
    /// Where to save each run's lit image (`crate::report::sweep_image_path` under it, at most
    /// [`IMAGE_WIDTH`] pixels wide), for the report; None saves none.
    pub images: Option<std::path::PathBuf>,
}

/// The widest a saved sweep image is (wider frames are scaled down).
pub const IMAGE_WIDTH: u32 = 320;

impl Default for SweepOptions {
    fn default() -> Self {
        Self {
            width: 1280,
            height: 720,
            repeat: 5,
            batch: 48,
            light_size: None,
            images: None,
        }
    }
}

/// The median of `v` (the upper middle for an even count; NaN when empty).
pub(crate) fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The shadow and camera GPU times of the frame whose total is the (upper) median of `frames`'
/// totals; NaN where no frame has timestamps.
fn median_split(frames: &[FrameStats]) -> (f64, f64) {
    let mut v: Vec<(f64, f64)> = frames
        .iter()
        .filter_map(|s| Some((s.gpu_shadow_ms?, s.gpu_camera_ms?)))
        .collect();
    v.sort_by(|a, b| (a.0 + a.1).total_cmp(&(b.0 + b.1)));
    v.get(v.len() / 2).copied().unwrap_or((f64::NAN, f64::NAN))
}

/// One view of a sweep: the scene's name and the view's, and its camera.
#[derive(Clone, Copy, Debug)]
pub struct SweepView<'a> {
    /// The scene's name (the rows' `scene`).
    pub scene: &'a str,
    /// The view's name (the rows' `view`).
    pub name: &'a str,
    /// The camera.
    pub camera: Camera,
}

/// Where a sweep's results go: each row as it is made, and a tick per unit of progress.
pub struct Sink<'a> {
    /// Called with each row.
    pub on_row: &'a mut dyn FnMut(Row),
    /// Called once per configuration scored and per configuration per timing round.
    pub tick: &'a mut dyn FnMut(),
}

/// Renders `view` with every configuration of `configs` that `skip` does not name and
/// hands each row to `sink.on_row`; `sink.tick` is called once per configuration scored and once per
/// configuration per timing round (`repeat + 1` ticks per configuration). Configurations go in
/// batches of `opts.batch`: every configuration of a batch is first scored once against the exact
/// reference (ray-cast once per view: it does not depend on shadow settings); then the batch's
/// frames are timed in `repeat` interleaved rounds (one frame of every configuration per round,
/// so drift of a shared machine spreads over all configurations instead of biasing some), taking
/// the median; then its rows are handed over. Within a round configurations go in order of map
/// format and size, and a frame whose map changed is rendered once untimed first (allocation and
/// first touch are not the configuration's cost).
pub fn run_view(
    renderer: &mut Renderer,
    reference: &ReferenceScene,
    view: &SweepView,
    configs: &[Config],
    opts: &SweepOptions,
    skip: &dyn Fn(&str) -> bool,
    sink: &mut Sink,
) -> Result<(), GpuError> {
    let todo: Vec<&Config> = configs.iter().filter(|c| !skip(&c.name())).collect();
    let mut exact: Option<ReferenceFrame> = None;
    for batch in todo.chunks(opts.batch.max(1)) {
        run_batch(
            renderer,
            reference,
            view,
            batch.to_vec(),
            opts,
            &mut exact,
            sink,
        )?;
    }
    Ok(())
}

fn run_batch(
    renderer: &mut Renderer,
    reference: &ReferenceScene,
    view: &SweepView,
    mut todo: Vec<&Config>,
    opts: &SweepOptions,
    exact: &mut Option<ReferenceFrame>,
    sink: &mut Sink,
) -> Result<(), GpuError> {
    let SweepView {
        scene,
        name: view_name,
        camera,
    } = *view;
    let Sink { on_row, tick } = sink;
    let (w, h) = (opts.width, opts.height);
    if todo.is_empty() {
        return Ok(());
    }
    todo.sort_by_key(|c| {
        (
            c.shadow.format == umbra::plan::ShadowFormat::D32,
            c.shadow.map_size,
        )
    });
    let view_of = |c: &Config, mode: ViewMode| {
        let mut v = View::new(camera);
        v.shadow = c.shadow;
        v.mode = mode;
        v.light_size = opts.light_size;
        v
    };
    // Accuracy, once per configuration.
    let mut scored = Vec::with_capacity(todo.len());
    for c in &todo {
        let s = crate::score::score(
            renderer,
            reference,
            &view_of(c, ViewMode::Lit),
            (w, h),
            exact,
        )?;
        let (m, lit) = (s.metrics, s.lit);
        if let Some(dir) = &opts.images {
            let p = crate::report::sweep_image_path(dir, scene, view_name, &c.name());
            if let Err(e) = save_image(&p, &lit.image) {
                // The images are for the report: a sweep goes on without one.
                log::warn!("sweep image not saved: {}: {e}", p.display());
            }
        }
        scored.push((m, lit.plan.primary_views().len().max(1) as u32));
        tick();
    }
    let stats = time_rounds(renderer, &todo, &view_of, opts, tick)?;
    let device = renderer.context().device_name.clone();
    for ((c, (m, layers)), st) in todo.iter().zip(scored).zip(stats) {
        on_row(row(view, c, &m, layers, &st, opts, &device));
    }
    Ok(())
}

/// Times every configuration of `todo` in `opts.repeat` interleaved rounds (one frame of each per
/// round, so drift of a shared machine spreads over all of them); a frame whose map changed is
/// rendered once untimed first. Returns each configuration's frames.
fn time_rounds(
    renderer: &mut Renderer,
    todo: &[&Config],
    view_of: &dyn Fn(&Config, ViewMode) -> View,
    opts: &SweepOptions,
    tick: &mut dyn FnMut(),
) -> Result<Vec<Vec<FrameStats>>, GpuError> {
    let (w, h) = (opts.width, opts.height);
    let mut stats: Vec<Vec<FrameStats>> = vec![Vec::new(); todo.len()];
    for _ in 0..opts.repeat.max(1) {
        let mut last_map = None;
        for (k, c) in todo.iter().enumerate() {
            let v = view_of(c, ViewMode::Lit);
            let map = (
                c.shadow.format == umbra::plan::ShadowFormat::D32,
                c.shadow.map_size,
            );
            if last_map != Some(map) {
                renderer.render(&v, w, h)?;
                last_map = Some(map);
            }
            stats[k].push(renderer.render(&v, w, h)?.stats);
            tick();
        }
    }
    Ok(stats)
}

/// The row of configuration `c` on `view`: its accuracy `m` (`layers` shadow views) and the
/// medians of its timed frames `st`.
fn row(
    view: &SweepView,
    c: &Config,
    m: &Metrics,
    layers: u32,
    st: &[FrameStats],
    opts: &SweepOptions,
    device: &str,
) -> Row {
    let pick = |f: &dyn Fn(&FrameStats) -> Option<f64>| {
        median(st.iter().filter_map(f).collect::<Vec<_>>())
    };
    // The median frame by GPU time, split into its two passes: the split of one frame adds up
    // to its total, where medians taken pass by pass need not (a compile stall in the shadow
    // pass of one frame and the camera pass of another counts twice).
    let gpu = median_split(st);
    let bytes = match c.shadow.format {
        umbra::plan::ShadowFormat::D16 => 2.0,
        // `auto` may take either: its memory is D32's at most.
        _ => 4.0,
    };
    Row {
        scene: view.scene.into(),
        view: view.name.into(),
        config: c.name(),
        method: c.method(),
        filter: c.filter().into(),
        format: format_name(c.shadow.format).into(),
        bias: c.bias.into(),
        map_texels: c.shadow.map_size,
        shadow_views: layers,
        shadow_memory_mib: (c.shadow.map_size as f64).powi(2) * bytes * layers as f64
            / (1024.0 * 1024.0),
        gpu_shadow_ms: gpu.0,
        gpu_camera_ms: gpu.1,
        gpu_ms: gpu.0 + gpu.1,
        wall_ms: pick(&|s| Some(s.wall_ms)),
        misclassified: m.misclassified,
        false_shadow: m.false_shadow,
        false_light: m.false_light,
        edge_misclassified: m.edge_misclassified,
        interior_misclassified: m.interior_misclassified,
        psnr_db: m.psnr.min(PSNR_IDENTICAL_DB),
        flip: m.flip,
        judged_pixels: m.judged_pixels as u64,
        width_px: opts.width,
        height_px: opts.height,
        frames: st.len() as u32,
        device: device.into(),
    }
}

/// Saves `img` at `path`, scaled down to [`IMAGE_WIDTH`] where wider.
fn save_image(path: &Path, img: &image::RgbaImage) -> Result<(), String> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
    }
    let (w, h) = img.dimensions();
    let small;
    let img = if w > IMAGE_WIDTH {
        let sh = (h as u64 * IMAGE_WIDTH as u64 / w as u64).max(1) as u32;
        small =
            image::imageops::resize(img, IMAGE_WIDTH, sh, image::imageops::FilterType::Triangle);
        &small
    } else {
        img
    };
    img.save(path).map_err(|e| e.to_string())
}

/// One row per configuration of `rows`, its numbers averaged over the rows of that configuration
/// (views, or scenes and views), named `scene` and `view` = `"all"` where they differ. In the
/// order configurations first appear.
pub fn mean_by_config(rows: &[Row]) -> Vec<Row> {
    let mut out: Vec<(Row, usize)> = Vec::new();
    for r in rows {
        match out.iter_mut().find(|(o, _)| o.config == r.config) {
            None => out.push((r.clone(), 1)),
            Some((o, n)) => {
                *n += 1;
                if o.scene != r.scene {
                    o.scene = "all".into();
                }
                if o.view != r.view {
                    o.view = "all".into();
                }
                for (a, b) in [
                    (&mut o.shadow_memory_mib, r.shadow_memory_mib),
                    (&mut o.gpu_shadow_ms, r.gpu_shadow_ms),
                    (&mut o.gpu_camera_ms, r.gpu_camera_ms),
                    (&mut o.gpu_ms, r.gpu_ms),
                    (&mut o.wall_ms, r.wall_ms),
                    (&mut o.misclassified, r.misclassified),
                    (&mut o.false_shadow, r.false_shadow),
                    (&mut o.false_light, r.false_light),
                    (&mut o.edge_misclassified, r.edge_misclassified),
                    (&mut o.interior_misclassified, r.interior_misclassified),
                    (&mut o.psnr_db, r.psnr_db),
                    (&mut o.flip, r.flip),
                ] {
                    *a += b;
                }
            }
        }
    }
    out.into_iter()
        .map(|(mut o, n)| {
            let k = n as f64;
            for a in [
                &mut o.shadow_memory_mib,
                &mut o.gpu_shadow_ms,
                &mut o.gpu_camera_ms,
                &mut o.gpu_ms,
                &mut o.wall_ms,
                &mut o.misclassified,
                &mut o.false_shadow,
                &mut o.false_light,
                &mut o.edge_misclassified,
                &mut o.interior_misclassified,
                &mut o.psnr_db,
                &mut o.flip,
            ] {
                *a /= k;
            }
            o
        })
        .collect()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    pub(crate) fn row(scene: &str, config: &str, gpu_ms: f64, misclassified: f64) -> Row {
        Row {
            scene: scene.into(),
            view: "default".into(),
            config: config.into(),
            method: "camera".into(),
            filter: "pcf2x2".into(),
            format: "d32".into(),
            bias: "default".into(),
            map_texels: 2048,
            shadow_views: 1,
            shadow_memory_mib: 16.0,
            gpu_shadow_ms: gpu_ms * 0.3,
            gpu_camera_ms: gpu_ms * 0.7,
            gpu_ms,
            wall_ms: gpu_ms + 10.0,
            misclassified,
            false_shadow: misclassified * 0.25,
            false_light: misclassified * 0.75,
            edge_misclassified: 0.1,
            interior_misclassified: 1e-5,
            psnr_db: PSNR_IDENTICAL_DB,
            flip: 0.012_345_678_9,
            judged_pixels: 812_345,
            width_px: 1280,
            height_px: 720,
            frames: 5,
            device: "llvmpipe (LLVM 15.0.6, 256 bits)".into(),
        }
    }

    #[test]
    fn a_rows_gpu_split_is_one_frames_split() {
        let f = |shadow: f64, camera: f64| FrameStats {
            gpu_shadow_ms: Some(shadow),
            gpu_camera_ms: Some(camera),
            ..Default::default()
        };
        // A stall in the shadow pass of one frame and in the camera pass of another: medians
        // pass by pass would give 7 + 6 = 13 for a median frame of 9.
        let frames = [f(7.0, 2.0), f(2.0, 6.0), f(2.0, 2.0)];
        assert_eq!(median_split(&frames), (2.0, 6.0));
        assert!(median_split(&[]).0.is_nan());
    }

    #[test]
    fn csv_round_trip_and_append_resume() {
        let dir = std::env::temp_dir().join(format!("umbra-sweep-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("sweep.csv");
        let _ = std::fs::remove_file(&path);
        let rows = vec![row("demo", "a", 12.5, 0.001), row("demo", "b", 30.25, 0.0)];
        let mut w = CsvAppender::open(&path).unwrap();
        for r in &rows {
            w.push(r).unwrap();
        }
        drop(w);
        assert_eq!(
            read_csv(&path).unwrap(),
            rows,
            "exact round trip of every column"
        );
        // Resume: append to the existing file, no second header.
        let mut a = CsvAppender::open(&path).unwrap();
        a.push(&row("town", "a", 40.0, 0.01)).unwrap();
        drop(a);
        let back = read_csv(&path).unwrap();
        assert_eq!(back.len(), 3);
        assert_eq!(back[2].scene, "town");
        // A fresh file gets its header from the appender.
        let fresh = dir.join("fresh.csv");
        let _ = std::fs::remove_file(&fresh);
        CsvAppender::open(&fresh).unwrap().push(&rows[0]).unwrap();
        assert_eq!(read_csv(&fresh).unwrap(), rows[..1]);
        assert!(read_csv(&dir.join("absent.csv")).unwrap().is_empty());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn mean_by_config_averages_over_views_and_scenes() {
        let mut b = row("town", "a", 30.0, 0.003);
        b.view = "street".into();
        let rows = vec![
            row("demo", "a", 10.0, 0.001),
            row("demo", "b", 20.0, 0.0),
            b,
        ];
        let m = mean_by_config(&rows);
        assert_eq!(m.len(), 2);
        assert_eq!((m[0].scene.as_str(), m[0].view.as_str()), ("all", "all"));
        assert!((m[0].gpu_ms - 20.0).abs() < 1e-12 && (m[0].misclassified - 0.002).abs() < 1e-12);
        assert_eq!(m[1], rows[1]);
    }
}
