//! The `umbra` binary: parse, call the library, report. Errors print one line and exit 1.

mod app;

use anyhow::Context as _;
use app::bench::{bench, median_of};
#[cfg(feature = "viewer")]
use app::cli::ViewArgsCmd;
use app::cli::{load_scene, make_view, scene_options, Cli, Command, RenderArgs};
#[cfg(feature = "reference")]
use app::lab_commands::compare;
#[cfg(feature = "sweep")]
use app::lab_commands::{stability, sweep};
use clap::Parser;
use umbra::gpu::{Context, ContextDesc, Validation};
use umbra::render::{FrameStats, Renderer};

fn main() {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn"))
        .format_timestamp(None)
        .init();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(a) => render(a),
        #[cfg(feature = "reference")]
        Command::Compare(a) => compare(a),
        #[cfg(feature = "viewer")]
        Command::View(a) => view(a),
        Command::Bench(a) => bench(a),
        Command::Inspect(a) => inspect(a),
        #[cfg(feature = "sweep")]
        Command::Sweep(a) => sweep(a),
        #[cfg(feature = "sweep")]
        Command::Stability(a) => stability(a),
        Command::Report(a) => report(&a.dir, a.output.as_deref()),
    };
    if let Err(e) = result {
        let msg = format!("{e:#}").replace('\n', " ");
        eprintln!("error: {msg}");
        std::process::exit(1);
    }
}

/// `umbra report DIR` and the commands' `--report`: writes the page, says what it holds.
fn report(dir: &std::path::Path, out: Option<&std::path::Path>) -> anyhow::Result<()> {
    let summary = umbra_lab::report::write(dir, out)?;
    eprintln!("report: {summary}");
    Ok(())
}

/// An offscreen context on `device` with the binary's pipeline cache, validated when asked.
fn offscreen_context(
    validation: bool,
    device: Option<String>,
) -> anyhow::Result<std::sync::Arc<Context>> {
    Ok(Context::new(&ContextDesc {
        validation: Validation::required_if(validation),
        device,
        pipeline_cache: app::pipeline_cache_path(),
        ..Default::default()
    })?)
}

/// Destroys the context (its renderers must be gone) and fails if the validation layer reported
/// anything of warning or error severity, destroy-time and leak messages included.
fn finish_context(ctx: std::sync::Arc<Context>) -> anyhow::Result<()> {
    let log = ctx.validation_log.clone();
    drop(ctx);
    if log.problem_count() > 0 {
        anyhow::bail!(
            "{} validation message(s) of warning or error severity",
            log.problem_count()
        );
    }
    Ok(())
}

/// `render --frames N`: the animation from `--time` at `--fps`, one PNG per frame.
fn render_sequence(a: &RenderArgs, frames: u32) -> anyhow::Result<()> {
    let mut scene = load_scene(a.scene.as_ref(), &a.view)?;
    // Without --time or --animation a sequence plays the first animation from 0.
    let first = umbra::scene::anim::Playing::first(scene.rig.as_deref());
    let (playing, t0) = app::cli::playing(&scene, &a.view)?.unwrap_or((first, 0.0));
    // Every name first, so a bad pattern fails before any rendering.
    let paths = (0..frames)
        .map(|i| app::cli::frame_path(&a.output, i))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let view = make_view(&scene, &a.view)?;
    let ctx = offscreen_context(a.validation, a.device.clone())?;
    let options = app::cli::animated_scene_options(&a.view);
    let mut renderer = Renderer::with_options(&ctx, &scene, &options)?;
    app::cli::warn_msaa(&a.view, renderer.samples());
    let (w, h) = a.view.size;
    let mut walls = Vec::with_capacity(paths.len());
    for (i, path) in paths.iter().enumerate() {
        let t = t0 + i as f32 / a.fps;
        let start = std::time::Instant::now();
        if scene.moves() {
            scene.pose_at(&playing, t);
            renderer.set_pose(&scene)?;
        }
        let frame = renderer.render(&view, w, h)?;
        walls.push((start.elapsed().as_secs_f64() * 1e3, frame.stats));
        frame
            .image
            .save(path)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    let stats: Vec<FrameStats> = walls.iter().map(|(_, s)| s.clone()).collect();
    let mut posed: Vec<f64> = walls.iter().map(|(w, _)| *w).collect();
    posed.sort_by(f64::total_cmp);
    let gpu = median_of(&stats, &|s| Some(s.gpu_shadow_ms? + s.gpu_camera_ms?));
    let shadow = median_of(&stats[1.min(stats.len() - 1)..], &|s| s.gpu_shadow_ms);
    let casters = median_of(&stats[1.min(stats.len() - 1)..], &|s| {
        Some(s.casters_drawn as f64)
    });
    let ms = |v: Option<f64>| v.map_or("n/a".into(), |g| format!("{g:.2} ms"));
    println!(
        "rendered {} frames of {} at {} fps from t = {t0} s ({}x{}, {} triangles, shadow cache {}) on {}: median per frame {:.1} ms with posing and upload, GPU {}; after the first frame shadow pass {}, casters drawn {} -> {}",
        paths.len(), scene.name, a.fps, w, h, renderer.triangles(),
        if options.shadow_cache { "on" } else { "off" }, ctx.device_name,
        posed[posed.len() / 2], ms(gpu), ms(shadow), casters.unwrap_or(0.0),
        a.output.display()
    );
    drop(renderer);
    finish_context(ctx)
}

fn render(a: RenderArgs) -> anyhow::Result<()> {
    if let Some(n) = a.frames {
        return render_sequence(&a, n);
    }
    if let Some(poses) = &a.views {
        return app::views::render_views(&a, poses);
    }
    let scene = load_scene(a.scene.as_ref(), &a.view)?;
    let mut view = make_view(&scene, &a.view)?;
    let ctx = offscreen_context(a.validation, a.device.clone())?;
    let mut renderer = Renderer::with_options(&ctx, &scene, &scene_options(&a.view))?;
    app::cli::warn_msaa(&a.view, renderer.samples());
    app::cli::apply_budget(&scene, &mut view, &a.view, &mut renderer)?;
    let (w, h) = a.view.size;
    let n = a.repeat.max(1);
    // Only the last frame's pixels are kept; the others contribute their timings.
    let mut all = Vec::with_capacity(n);
    let mut frame = renderer.render(&view, w, h)?;
    for _ in 1..n {
        all.push(frame.stats);
        frame = renderer.render(&view, w, h)?;
    }
    all.push(frame.stats.clone());
    app::cli::warn_exact(&view, &frame.plan);
    frame
        .image
        .save(&a.output)
        .with_context(|| format!("writing {}", a.output.display()))?;
    let median = |f: &dyn Fn(&FrameStats) -> Option<f64>| median_of(&all, f);
    let wall = median(&|s| Some(s.wall_ms)).unwrap_or(0.0);
    let gpu = match (median(&|s| s.gpu_shadow_ms), median(&|s| s.gpu_camera_ms)) {
        (Some(a), Some(b)) => format!(
            "GPU {:.1} ms (shadow {a:.1} + camera {b:.1})",
            median(&|s| Some(s.gpu_shadow_ms? + s.gpu_camera_ms?)).unwrap_or(a + b)
        ),
        _ => "GPU time n/a".into(),
    };
    let s = &frame.stats;
    let what = if n > 1 {
        format!("median of {n} frames: ")
    } else {
        String::new()
    };
    println!(
        "rendered {} ({} triangles, {} draws of which {} deferred and {} unshadowed beyond the casters' reach, {} casters drawn, {} shadow view(s){}) at {}x{} on {}: {what}wall {wall:.1} ms, {gpu} -> {}",
        scene.name, s.triangles, s.draws, s.deferred_draws, s.unshadowed_draws, s.casters_drawn, if frame.plan.shadows_on { frame.plan.shadow_views.len() } else { 0 }, grid_note(&frame), frame.image.width(), frame.image.height(), ctx.device_name, a.output.display()
    );
    let t = renderer.texture_stats();
    if t.file_mips > 0 {
        println!(
            "textures: {} images, {:.1} MiB on the device; {} KTX2 with the file's mips, {} as BC7",
            t.images,
            t.bytes as f64 / (1 << 20) as f64,
            t.file_mips,
            t.bc7
        );
    }
    // Count after the renderer and the context are gone, so destroy-time and leak messages count.
    drop(renderer);
    finish_context(ctx)
}

/// The render line's note on exact and hybrid shadows: the method, and the caster triangles
/// drawn into the grid of those the frame has.
fn grid_note(frame: &umbra::RenderedFrame) -> String {
    let method = if frame.plan.hybrid_shadows() {
        "hybrid"
    } else if frame.plan.exact_shadows() {
        "exact"
    } else if frame.plan.contact_shadows() {
        return ", contact shadows".into();
    } else {
        return String::new();
    };
    match frame.stats.grid_triangles {
        Some((drawn, all)) => format!(", {method}: {drawn} of {all} caster triangles in the grid"),
        None => format!(", {method}"),
    }
}

#[cfg(feature = "viewer")]
fn view(a: ViewArgsCmd) -> anyhow::Result<()> {
    let scene = load_scene(a.scene.as_ref(), &a.view)?;
    let mut view = make_view(&scene, &a.view)?;
    if view.supersample > 1 {
        eprintln!(
            "warning: --ssaa {}: the viewer draws at its window's size; ignored",
            view.supersample
        );
        view.supersample = 1;
    }
    let start = app::cli::playing(&scene, &a.view)?;
    let args = a.view.clone();
    app::viewer::run(app::viewer::ViewerOptions {
        scene,
        path: a.scene.clone(),
        loader: Box::new(move |p| {
            let s = load_scene(Some(&p.to_path_buf()), &args)?;
            if s.triangle_count() == 0 {
                anyhow::bail!("{}: nothing to draw", p.display());
            }
            Ok(s)
        }),
        view,
        size: a.view.size,
        scene_options: app::cli::animated_scene_options(&a.view),
        vsync: !a.no_vsync,
        frames: a.frames,
        screenshot: a.screenshot,
        screenshot_ui: a.screenshot_ui,
        panel: !a.no_panel,
        device: a.device,
        validation: a.validation,
        script: app::script::expand(&a.script).map_err(|e| anyhow::anyhow!("--script: {e}"))?,
        shadow_budget: a.view.shadow_budget,
        start,
    })
}

fn inspect(a: app::cli::InspectArgs) -> anyhow::Result<()> {
    if a.view.synthetic.is_some() {
        anyhow::bail!("inspect reads a glTF file; --synthetic does not apply");
    }
    let scene = umbra::load_gltf(&a.scene)?;
    let view = make_view(&scene, &a.view)?;
    let mut report = umbra::scene::inspect::document_report(&a.scene, &scene)?;
    let (w, h) = a.view.size;
    report["shadow_plan"] = umbra::plan::report::plan_report(&scene, &view, w, h);
    report["exposure"] = umbra::plan::report::exposure_report(&scene, &view, w, h);
    if a.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{}", app::inspect_view::format_report(&report, a.md));
    }
    Ok(())
}
