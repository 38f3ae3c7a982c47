//! The `umbra` binary: parse, call the library, report. Errors print one line and exit 1.

use anyhow::Context as _;
use clap::Parser;
use umbra::app::cli::{load_scene, make_view, Cli, Command, RenderArgs};
use umbra::gpu::{Context, ContextDesc, Validation};
use umbra::render::Renderer;

fn main() {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn"))
        .format_timestamp(None)
        .init();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(a) => render(a),
    };
    if let Err(e) = result {
        let msg = format!("{e:#}").replace('\n', " ");
        eprintln!("error: {msg}");
        std::process::exit(1);
    }
}

fn render(a: RenderArgs) -> anyhow::Result<()> {
    let scene = load_scene(a.scene.as_ref(), a.view.ground)?;
    for w in &scene.warnings {
        eprintln!("warning: {}: {w}", scene.name);
    }
    let view = make_view(&scene, &a.view)?;
    let ctx = Context::new(&ContextDesc {
        validation: if a.validation {
            Validation::Required
        } else {
            Validation::Off
        },
        device: a.device.clone(),
        ..Default::default()
    })?;
    let mut renderer = Renderer::new(&ctx, &scene)?;
    let (w, h) = a.view.size;
    let n = a.repeat.max(1);
    let mut frames = Vec::with_capacity(n);
    for _ in 0..n {
        frames.push(renderer.render(&view, w, h)?);
    }
    let frame = frames.pop().expect("one frame");
    frame
        .image
        .save(&a.output)
        .with_context(|| format!("writing {}", a.output.display()))?;
    let mut all: Vec<_> = frames.iter().map(|f| f.stats.clone()).collect();
    all.push(frame.stats.clone());
    let median = |f: &dyn Fn(&umbra::render::FrameStats) -> Option<f64>| -> Option<f64> {
        let mut v: Vec<f64> = all.iter().filter_map(f).collect();
        v.sort_by(f64::total_cmp);
        (!v.is_empty()).then(|| v[v.len() / 2])
    };
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
        "rendered {} ({} triangles, {} casters drawn) at {}x{} on {}: {what}wall {wall:.1} ms, {gpu} -> {}",
        scene.name, s.triangles, s.casters_drawn, frame.image.width(), frame.image.height(), ctx.device_name, a.output.display()
    );
    if ctx.validation_log.problem_count() > 0 {
        anyhow::bail!(
            "{} validation message(s) of warning or error severity",
            ctx.validation_log.problem_count()
        );
    }
    Ok(())
}
