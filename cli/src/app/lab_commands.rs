//! The commands that judge frames with the lab: `compare` (against the ray-cast reference),
//! `stability` and `sweep`.

#[cfg(feature = "reference")]
use crate::app::cli::CompareArgs;
use crate::app::cli::{load_scene, make_view, scene_options};
#[cfg_attr(not(feature = "sweep"), allow(unused_imports))]
use crate::{finish_context, offscreen_context};
use anyhow::Context as _;
use umbra::render::Renderer;

#[cfg(feature = "reference")]
pub(crate) fn compare(a: CompareArgs) -> anyhow::Result<()> {
    use umbra_lab::reference::ReferenceScene;
    use umbra_lab::score;
    let scene = load_scene(a.scene.as_ref(), &a.view)?;
    let mut view = make_view(&scene, &a.view)?;
    let ctx = offscreen_context(a.validation, a.device.clone())?;
    let mut renderer = Renderer::with_options(&ctx, &scene, &scene_options(&a.view))?;
    crate::app::cli::warn_msaa(&a.view, renderer.samples());
    crate::app::cli::apply_budget(&scene, &mut view, &a.view, &mut renderer)?;
    let (w, h) = a.view.size;
    let t0 = std::time::Instant::now();
    let reference = ReferenceScene::new(&scene);
    let build_ms = t0.elapsed().as_secs_f64() * 1e3;
    let mut exact = None;
    let scored = score(&mut renderer, &reference, &view, (w, h), &mut exact)?;
    let reference_ms = build_ms + scored.reference_ms;
    let (metrics, diff, lit) = (&scored.metrics, &scored.diff, &scored.lit);
    crate::app::cli::warn_exact(&view, &lit.plan);
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
    j["shadow_method"] = serde_json::json!(if lit.plan.hybrid_shadows() {
        "hybrid"
    } else if lit.plan.exact_shadows() {
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
    drop(renderer);
    finish_context(ctx)?;
    let p = a.out.join("compare.json");
    std::fs::write(&p, format!("{j:#}\n")).with_context(|| format!("writing {}", p.display()))?;
    if a.report {
        crate::report(&a.out, None)?;
    }
    Ok(())
}

/// `DIR/depth_profile.svg|png`: misclassified fraction per view-depth bin (log-log), the
/// cascade splits marked on the line.
#[cfg(all(feature = "reference", feature = "sweep"))]
pub(crate) fn write_depth_profile(
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

#[cfg(feature = "sweep")]
pub(crate) fn stability(a: crate::app::cli::StabilityArgs) -> anyhow::Result<()> {
    use umbra_lab::analysis::stability::{report, StabilityOptions};
    let spec = if a.builtin {
        "stability".to_string()
    } else {
        a.scene.clone().unwrap_or_else(|| "demo".into())
    };
    let scene = crate::app::cli::load_named(&spec, a.ground)?;
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
    if a.report {
        crate::report(&a.out, None)?;
    }
    if a.strict && failed > 0 {
        anyhow::bail!("{failed} stability threshold(s) not met");
    }
    Ok(())
}

#[cfg(feature = "sweep")]
pub(crate) fn sweep(a: crate::app::cli::SweepArgs) -> anyhow::Result<()> {
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
        .map(|s| crate::app::cli::load_named(s, a.ground))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let (width, height) = a.size;
    let opts = SweepOptions {
        width,
        height,
        repeat: a.repeat,
        light_size: a.light_size,
        images: (a.images || a.report).then(|| a.out.clone()),
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
    finish_context(ctx)?;
    if a.report {
        crate::report(&a.out, None)?;
    }
    Ok(())
}

/// One line per `--check-budget` result.
#[cfg(feature = "sweep")]
pub(crate) fn print_budget_check(row: &umbra_lab::analysis::budget::CheckRow) {
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
