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
        Command::Inspect(a) => inspect(a),
        #[cfg(feature = "sweep")]
        Command::Sweep(a) => sweep(a),
        #[cfg(feature = "sweep")]
        Command::Stability(a) => stability(a),
    };
    if let Err(e) = result {
        let msg = format!("{e:#}").replace('\n', " ");
        eprintln!("error: {msg}");
        std::process::exit(1);
    }
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
        scene.name, s.triangles, s.draws, s.deferred_draws, s.unshadowed_draws, s.casters_drawn, if frame.plan.shadows_on { frame.plan.shadow_views.len() } else { 0 }, if frame.plan.exact_shadows() { ", exact" } else if frame.plan.contact_shadows() { ", contact shadows" } else { "" }, frame.image.width(), frame.image.height(), ctx.device_name, a.output.display()
    );
    // Count after the renderer and the context are gone, so destroy-time and leak messages count.
    drop(renderer);
    finish_context(ctx)
}

#[cfg(feature = "reference")]
fn compare(a: CompareArgs) -> anyhow::Result<()> {
    use umbra_lab::reference::ReferenceScene;
    use umbra_lab::score;
    let scene = load_scene(a.scene.as_ref(), &a.view)?;
    let mut view = make_view(&scene, &a.view)?;
    let ctx = offscreen_context(false, a.device.clone())?;
    let mut renderer = Renderer::with_options(&ctx, &scene, &scene_options(&a.view))?;
    app::cli::warn_msaa(&a.view, renderer.samples());
    app::cli::apply_budget(&scene, &mut view, &a.view, &mut renderer)?;
    let (w, h) = a.view.size;
    let t0 = std::time::Instant::now();
    let reference = ReferenceScene::new(&scene);
    let build_ms = t0.elapsed().as_secs_f64() * 1e3;
    let mut exact = None;
    let scored = score(&mut renderer, &reference, &view, (w, h), &mut exact)?;
    let reference_ms = build_ms + scored.reference_ms;
    let (metrics, diff, lit) = (&scored.metrics, &scored.diff, &scored.lit);
    app::cli::warn_exact(&view, &lit.plan);
    let frame = exact.ok_or_else(|| anyhow::anyhow!("no reference frame"))?;
    std::fs::create_dir_all(&a.out).with_context(|| format!("creating {}", a.out.display()))?;
    for (name, img) in [
        ("gpu.png", &lit.image),
        ("reference.png", &frame.image),
        ("diff.png", diff),
        ("shadow.png", &scored.shadow),
        ("coverage.png", &frame.coverage_image()),
    ] {
        let p = a.out.join(name);
        img.save(&p)
            .with_context(|| format!("writing {}", p.display()))?;
    }
    let mut j = metrics.to_json();
    // Misclassification along view depth, and where the shown light's cascades split.
    let by_depth =
        umbra_lab::reference::misclassified_by_depth(&scored.classified, &frame, &lit.plan, 24);
    let splits: Vec<f32> = {
        let v = lit.plan.primary_views();
        v[..v.len().saturating_sub(1)]
            .iter()
            .map(|v| v.far)
            .collect()
    };
    j["by_depth"] = serde_json::json!(by_depth
        .iter()
        .map(|b| serde_json::json!({"near": b.near, "far": b.far, "judged": b.judged, "misclassified": b.wrong}))
        .collect::<Vec<_>>());
    j["cascade_splits"] = serde_json::json!(splits);
    #[cfg(feature = "sweep")]
    write_depth_profile(&a.out, &scene.name, &by_depth, &splits)?;
    j["scene"] = serde_json::json!(scene.name);
    j["size"] = serde_json::json!([w, h]);
    j["shadow_map"] = serde_json::json!(view.shadow.map_size);
    j["shadow_method"] = serde_json::json!(if lit.plan.exact_shadows() {
        "exact"
    } else if lit.plan.contact_shadows() {
        "map+contact"
    } else {
        "map"
    });
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

/// `DIR/depth_profile.svg|png`: misclassified fraction per view-depth bin (log-log), the
/// cascade splits marked on the line.
#[cfg(all(feature = "reference", feature = "sweep"))]
fn write_depth_profile(
    out: &std::path::Path,
    name: &str,
    bins: &[umbra_lab::reference::DepthBin],
    splits: &[f32],
) -> anyhow::Result<()> {
    use umbra_lab::analysis::lines::{write_lines, LineChart, Series};
    let centre = |b: &umbra_lab::reference::DepthBin| ((b.near * b.far).sqrt()) as f64;
    let points: Vec<(f64, f64)> = bins
        .iter()
        .filter(|b| b.judged > 0)
        .map(|b| (centre(b), b.fraction()))
        .collect();
    let at = |d: f32| {
        bins.iter()
            .find(|b| b.near <= d && d <= b.far)
            .map_or(0.0, |b| b.fraction())
    };
    let chart = LineChart {
        title: format!("{name}: misclassified pixels along view depth"),
        x_desc: "view depth (scene units)".into(),
        y_desc: "misclassified fraction of judged pixels (0 drawn at 1e-5)".into(),
        x_log: true,
        y_floor: 1e-5,
        series: vec![Series {
            label: "misclassified".into(),
            points,
        }],
        thresholds: Vec::new(),
        marks: splits
            .iter()
            .enumerate()
            .map(|(k, &d)| (format!("split {}", k + 1), (d as f64, at(d))))
            .collect(),
    };
    write_lines(
        &chart,
        &out.join("depth_profile.svg"),
        &out.join("depth_profile.png"),
    )
    .map_err(|e| anyhow::anyhow!("depth profile chart: {e}"))
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

#[cfg(feature = "sweep")]
fn stability(a: app::cli::StabilityArgs) -> anyhow::Result<()> {
    use umbra_lab::analysis::stability::{report, StabilityOptions};
    let spec = if a.builtin {
        "stability".to_string()
    } else {
        a.scene.clone().unwrap_or_else(|| "demo".into())
    };
    let scene = app::cli::load_named(&spec, a.ground)?;
    let (w, h) = a.size;
    let camera = umbra_lab::analysis::grid::sweep_views(&scene, w as f32 / h.max(1) as f32)
        .into_iter()
        .next()
        .map(|v| v.1)
        .ok_or_else(|| anyhow::anyhow!("{}: no view", scene.name))?;
    let view = umbra::plan::View::new(camera);
    let wall = (a.builtin || spec == "stability")
        .then_some(umbra::scene::built::synthetic::STABILITY_WALL_HALF);
    let ctx = offscreen_context(a.validation, a.device.clone())?;
    let bar = indicatif::ProgressBar::new(report::planned_steps(a.quick, wall.is_some()));
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{bar:40} {pos}/{len} [{elapsed_precise}, ETA {eta_precise}] {msg}",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let r = report::run(
        &ctx,
        &scene,
        &view,
        &Default::default(),
        &StabilityOptions {
            size: a.size,
            quick: a.quick,
            animation: match a.animation.as_deref() {
                Some(spec) => match umbra::scene::anim::Playing::parse(spec, scene.rig.as_deref())
                    .map_err(|e| anyhow::anyhow!(e))?
                {
                    umbra::scene::anim::Playing::One(i) => Some(i),
                    _ => anyhow::bail!("--animation: the motion probe plays one animation"),
                },
                None => None,
            },
        },
        wall,
        &mut |phase| {
            bar.set_message(phase.to_string());
            bar.inc(1);
        },
    )?;
    bar.finish_and_clear();
    report::write(&r, &a.out)?;
    let failed = r.verdicts.iter().filter(|v| v.pass == Some(false)).count();
    for v in &r.verdicts {
        let res = match v.pass {
            Some(true) => "pass",
            Some(false) => "FAIL",
            None => "n/a ",
        };
        println!("{res}  {}: {}", v.criterion, v.measured);
    }
    let total = r.seconds.last().map_or(0.0, |s| s.1);
    println!(
        "stability of {}: {} of {} thresholds met in {total:.0} s -> {}",
        scene.name,
        r.verdicts.len() - failed,
        r.verdicts.len(),
        a.out.join("stability.md").display()
    );
    finish_context(ctx)?;
    if a.strict && failed > 0 {
        anyhow::bail!("{failed} stability threshold(s) not met");
    }
    Ok(())
}

#[cfg(feature = "sweep")]
fn sweep(a: app::cli::SweepArgs) -> anyhow::Result<()> {
    use umbra_lab::analysis::campaign::{Campaign, Progress};
    use umbra_lab::analysis::{grid::Grid, sweep::SweepOptions};
    if let Some(s) = a.light_size {
        if !(s.is_finite() && s > 0.0 && s <= 1e6) {
            anyhow::bail!("--light-size must be a number within 0..1e6, above 0");
        }
    }
    let mut grid = if a.quick { Grid::quick() } else { Grid::full() };
    grid.sdsm = a.depth_fit;
    grid.exact = a.exact;
    grid.contact = a.contact;
    if !a.formats.is_empty() {
        grid.formats = a.formats.iter().filter_map(|f| f.parse().ok()).collect();
    }
    grid.pcss = a.light_size.is_some();
    let specs = if a.scenes.is_empty() {
        vec!["demo".to_string()]
    } else {
        a.scenes.clone()
    };
    let scenes = specs
        .iter()
        .map(|s| app::cli::load_named(s, a.ground))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let (width, height) = a.size;
    let opts = SweepOptions {
        width,
        height,
        repeat: a.repeat,
        light_size: a.light_size,
        ..Default::default()
    };
    let campaign = Campaign::new(&scenes, grid.configs(), a.views, opts, &a.out)?;
    let ctx = offscreen_context(a.validation, a.device.clone())?;
    let (total, already) = (campaign.total(), campaign.already());
    eprintln!(
        "sweep: {} scene(s), {} configuration(s) per view, {total} runs ({already} already in {}) on {}",
        scenes.len(),
        campaign.configs.len(),
        campaign.csv_path().display(),
        ctx.device_name
    );
    let bar = indicatif::ProgressBar::new(campaign.ticks_left());
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{bar:40} {percent}% [{elapsed_precise}, ETA {eta_precise}] {msg}",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let started = std::time::Instant::now();
    campaign.run(&ctx, &mut |p| match p {
        Progress::View(scene, view) => bar.set_message(format!("{scene} / {view}")),
        Progress::Tick => bar.inc(1),
    })?;
    bar.finish_and_clear();
    let (rows, names) = campaign.write_results()?;
    if a.features {
        let fit = a.fit_budget.then_some(ctx.device_name.as_str());
        campaign.write_features(&Grid::full().configs(), (&rows, &names), fit)?;
    }
    if !a.check_budget.is_empty() {
        campaign.check_budgets(&ctx, &rows, &a.check_budget, &mut print_budget_check)?;
    }
    println!(
        "swept {} run(s) in {:.1} s; {} rows in {} (+ sweep.json, pareto.svg/.png and {} per-scene chart(s))",
        total - already,
        started.elapsed().as_secs_f64(),
        rows.len(),
        campaign.csv_path().display(),
        names.len()
    );
    finish_context(ctx)
}

/// One line per `--check-budget` result.
#[cfg(feature = "sweep")]
fn print_budget_check(row: &umbra_lab::analysis::budget::CheckRow) {
    let at = format!(
        "budget {:.3} % on {} / {}",
        row.budget * 100.0,
        row.scene,
        row.view
    );
    if row.cheapest.is_empty() {
        println!(
            "{at}: no swept configuration meets it; chose {} ({:.4} %, the most accurate tried)",
            row.chosen,
            row.measured * 100.0
        );
    } else {
        println!(
            "{at}: {} measured {:.4} % ({}), {:.2}x the cheapest within budget ({}; {:.2}x by per-pass medians)",
            row.chosen,
            row.measured * 100.0,
            if row.within_budget { "within" } else { "OVER" },
            row.time_ratio,
            row.cheapest,
            row.denoised_time_ratio
        );
    }
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

/// The median of `f` over the frames that have a value for it.
fn median_of(frames: &[FrameStats], f: &dyn Fn(&FrameStats) -> Option<f64>) -> Option<f64> {
    let mut v: Vec<f64> = frames.iter().filter_map(f).collect();
    v.sort_by(f64::total_cmp);
    (!v.is_empty()).then(|| v[v.len() / 2])
}

/// Milliseconds with three significant digits down to a microsecond (GPU frames run from
/// tenths of a millisecond to hundreds).
fn fmt_ms(ms: f64) -> String {
    if ms < 1.0 {
        format!("{ms:.3}")
    } else if ms < 10.0 {
        format!("{ms:.2}")
    } else {
        format!("{ms:.1}")
    }
}

/// The anti-aliasing a frame gets, as a parenthesis after its size (empty without any).
fn anti_aliasing(samples: u32, view: &umbra::plan::View) -> String {
    let mut parts = Vec::new();
    if samples > 1 {
        parts.push(format!("{samples}× MSAA"));
    }
    if view.supersample > 1 {
        let s = view.supersample;
        parts.push(format!("{s}×{s} supersampled"));
    }
    if view.post_aa == umbra::plan::PostAa::Fxaa {
        parts.push("FXAA".to_string());
    }
    if parts.is_empty() {
        String::new()
    } else {
        format!(" ({})", parts.join(", "))
    }
}

fn bench(a: BenchArgs) -> anyhow::Result<()> {
    let scene = load_scene(a.scene.as_ref(), &a.view)?;
    let mut base = make_view(&scene, &a.view)?;
    let ctx = offscreen_context(false, a.device.clone())?;
    let mut renderer = Renderer::with_options(&ctx, &scene, &scene_options(&a.view))?;
    app::cli::warn_msaa(&a.view, renderer.samples());
    app::cli::apply_budget(&scene, &mut base, &a.view, &mut renderer)?;
    let (w, h) = a.view.size;
    println!(
        "{} ({} triangles) at {w}x{h}{} on {}; medians of {} frames after 1 warm-up",
        scene.name,
        renderer.triangles(),
        anti_aliasing(renderer.samples(), &base),
        ctx.device_name,
        a.repeat
    );
    println!();
    println!(
        "| shadow map | PCF | GPU shadow ms | GPU camera ms | GPU total ms | wall ms | casters |"
    );
    println!("|---|---|---|---|---|---|---|");
    // With a budget, the one chosen configuration.
    let budgeted = a.view.shadow_budget.is_some();
    let maps = if budgeted {
        vec![base.shadow.map_size]
    } else {
        a.maps.clone()
    };
    for &map in &maps {
        let kernels = if map == 0 || budgeted {
            &a.kernels[..a.kernels.len().min(1)]
        } else {
            &a.kernels[..]
        };
        for &k in kernels {
            let mut v = base.clone();
            v.shadow.enabled = map > 0;
            v.shadow.map_size = map.max(16);
            if !budgeted {
                v.shadow.pcf = pcf_of(k);
            }
            let side = renderer.render(&v, w, h)?.plan.shadow_map_size();
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
            // The automatic setting may draw one map of twice the side instead of cascades.
            let map_label = match map {
                0 => "off".to_string(),
                m if side != m => format!("{m}² (drawn {side}²)"),
                m => format!("{m}²"),
            };
            let pcf = if map == 0 {
                "-".to_string()
            } else {
                format!("{:?}", v.shadow.pcf)
            };
            println!(
                "| {map_label} | {pcf} | {} | {} | {} | {} | {} |",
                fmt_ms(sh),
                fmt_ms(cam),
                fmt_ms(tot),
                fmt_ms(wall),
                frames[0].casters_drawn
            );
        }
    }
    Ok(())
}
