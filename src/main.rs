//! The `umbra` binary: parse, call the library, report. Errors print one line and exit 1.

mod app;

use anyhow::Context as _;
#[cfg(feature = "reference")]
use app::cli::CompareArgs;
#[cfg(feature = "viewer")]
use app::cli::ViewArgsCmd;
use app::cli::{load_scene, make_view, pcf_of, scene_options, BenchArgs, Cli, Command, RenderArgs};
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
    };
    if let Err(e) = result {
        let msg = format!("{e:#}").replace('\n', " ");
        eprintln!("error: {msg}");
        std::process::exit(1);
    }
}

fn render(a: RenderArgs) -> anyhow::Result<()> {
    let scene = load_scene(a.scene.as_ref(), &a.view)?;
    let view = make_view(&scene, &a.view)?;
    let ctx = Context::new(&ContextDesc {
        validation: if a.validation {
            Validation::Required
        } else {
            Validation::Off
        },
        device: a.device.clone(),
        pipeline_cache: app::pipeline_cache_path(),
        ..Default::default()
    })?;
    let mut renderer = Renderer::with_options(&ctx, &scene, &scene_options(&a.view))?;
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
        "rendered {} ({} triangles, {} casters drawn, {} shadow view(s)) at {}x{} on {}: {what}wall {wall:.1} ms, {gpu} -> {}",
        scene.name, s.triangles, s.casters_drawn, frame.plan.shadow_views.len(), frame.image.width(), frame.image.height(), ctx.device_name, a.output.display()
    );
    // Count after the renderer and the context are gone, so destroy-time and leak messages count.
    let log = ctx.validation_log.clone();
    drop(renderer);
    drop(ctx);
    if log.problem_count() > 0 {
        anyhow::bail!(
            "{} validation message(s) of warning or error severity",
            log.problem_count()
        );
    }
    Ok(())
}

#[cfg(feature = "reference")]
fn compare(a: CompareArgs) -> anyhow::Result<()> {
    use umbra::reference::{compare as compare_frames, ReferenceScene};
    use umbra::render::ViewMode;
    let scene = load_scene(a.scene.as_ref(), &a.view)?;
    let mut view = make_view(&scene, &a.view)?;
    let ctx = Context::new(&ContextDesc {
        device: a.device.clone(),
        pipeline_cache: app::pipeline_cache_path(),
        ..Default::default()
    })?;
    let mut renderer = Renderer::with_options(&ctx, &scene, &scene_options(&a.view))?;
    renderer.set_read_depth(true);
    let (w, h) = a.view.size;
    view.mode = ViewMode::Lit;
    let lit = renderer.render(&view, w, h)?;
    view.mode = ViewMode::Shadow;
    let shadow = renderer.render(&view, w, h)?;
    let t0 = std::time::Instant::now();
    let reference = ReferenceScene::new(&scene);
    let build_ms = t0.elapsed().as_secs_f64() * 1e3;
    let frame = reference.render(&lit.plan, w, h, view.ambient);
    let reference_ms = t0.elapsed().as_secs_f64() * 1e3;
    let depth = lit
        .depth
        .as_deref()
        .ok_or_else(|| anyhow::anyhow!("no depth read back"))?;
    let (metrics, diff) = compare_frames(&lit.image, &shadow.image, depth, &lit.plan, &frame);
    std::fs::create_dir_all(&a.out).with_context(|| format!("creating {}", a.out.display()))?;
    for (name, img) in [
        ("gpu.png", &lit.image),
        ("reference.png", &frame.image),
        ("diff.png", &diff),
    ] {
        let p = a.out.join(name);
        img.save(&p)
            .with_context(|| format!("writing {}", p.display()))?;
    }
    let mut j = metrics.to_json();
    j["scene"] = serde_json::json!(scene.name);
    j["size"] = serde_json::json!([w, h]);
    j["shadow_map"] = serde_json::json!(view.shadow.map_size);
    j["bvh_build_ms"] = serde_json::json!(build_ms);
    j["reference_ms"] = serde_json::json!(reference_ms);
    j["gpu_ms"] = serde_json::json!(lit
        .stats
        .gpu_shadow_ms
        .zip(lit.stats.gpu_camera_ms)
        .map(|(s, c)| s + c));
    println!("{j}");
    Ok(())
}

#[cfg(feature = "viewer")]
fn view(a: ViewArgsCmd) -> anyhow::Result<()> {
    let scene = load_scene(a.scene.as_ref(), &a.view)?;
    let view = make_view(&scene, &a.view)?;
    app::viewer::run(app::viewer::ViewerOptions {
        scene,
        view,
        size: a.view.size,
        scene_options: scene_options(&a.view),
        vsync: !a.no_vsync,
        frames: a.frames,
        screenshot: a.screenshot,
        device: a.device,
        validation: a.validation,
        resize_script: a.resize_script,
    })
}

/// The median of `f` over the frames that have a value for it.
fn median_of(frames: &[FrameStats], f: &dyn Fn(&FrameStats) -> Option<f64>) -> Option<f64> {
    let mut v: Vec<f64> = frames.iter().filter_map(f).collect();
    v.sort_by(f64::total_cmp);
    (!v.is_empty()).then(|| v[v.len() / 2])
}

fn bench(a: BenchArgs) -> anyhow::Result<()> {
    let scene = load_scene(a.scene.as_ref(), &a.view)?;
    let base = make_view(&scene, &a.view)?;
    let ctx = Context::new(&ContextDesc {
        device: a.device.clone(),
        pipeline_cache: app::pipeline_cache_path(),
        ..Default::default()
    })?;
    let mut renderer = Renderer::with_options(&ctx, &scene, &scene_options(&a.view))?;
    let (w, h) = a.view.size;
    println!(
        "{} ({} triangles) at {w}x{h} on {}; medians of {} frames after 1 warm-up",
        scene.name,
        renderer.triangles(),
        ctx.device_name,
        a.repeat
    );
    println!();
    println!(
        "| shadow map | PCF | GPU shadow ms | GPU camera ms | GPU total ms | wall ms | casters |"
    );
    println!("|---|---|---|---|---|---|---|");
    for &map in &a.maps {
        let kernels = if map == 0 {
            &a.kernels[..a.kernels.len().min(1)]
        } else {
            &a.kernels[..]
        };
        for &k in kernels {
            let mut v = base.clone();
            v.shadow.enabled = map > 0;
            v.shadow.map_size = map.max(16);
            v.shadow.pcf = pcf_of(k);
            renderer.render(&v, w, h)?;
            let mut frames = Vec::new();
            for _ in 0..a.repeat.max(1) {
                frames.push(renderer.render(&v, w, h)?.stats);
            }
            let m =
                |f: &dyn Fn(&FrameStats) -> Option<f64>| median_of(&frames, f).unwrap_or(f64::NAN);
            let sh = m(&|s| s.gpu_shadow_ms);
            let cam = m(&|s| s.gpu_camera_ms);
            let tot = m(&|s| Some(s.gpu_shadow_ms? + s.gpu_camera_ms?));
            let wall = m(&|s| Some(s.wall_ms));
            let map_label = if map == 0 {
                "off".to_string()
            } else {
                format!("{map}²")
            };
            let pcf = if map == 0 {
                "-".to_string()
            } else {
                format!("{:?}", v.shadow.pcf)
            };
            println!(
                "| {map_label} | {pcf} | {sh:.1} | {cam:.1} | {tot:.1} | {wall:.1} | {} |",
                frames[0].casters_drawn
            );
        }
    }
    Ok(())
}
