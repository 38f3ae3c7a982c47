//! `umbra bench`: medians of N offscreen frames, GPU time per pass and wall time, as a table.

use crate::app::cli::{load_scene, make_view, pcf_of, scene_options, BenchArgs};
use crate::offscreen_context;
use umbra::render::{FrameStats, Renderer};

/// The median of `f` over the frames that have a value for it.
pub(crate) fn median_of(
    frames: &[FrameStats],
    f: &dyn Fn(&FrameStats) -> Option<f64>,
) -> Option<f64> {
    let mut v: Vec<f64> = frames.iter().filter_map(f).collect();
    v.sort_by(f64::total_cmp);
    (!v.is_empty()).then(|| v[v.len() / 2])
}

/// Milliseconds with three significant digits down to a microsecond (GPU frames run from
/// tenths of a millisecond to hundreds).
pub(crate) fn fmt_ms(ms: f64) -> String {
    if ms < 1.0 {
        format!("{ms:.3}")
    } else if ms < 10.0 {
        format!("{ms:.2}")
    } else {
        format!("{ms:.1}")
    }
}

/// The anti-aliasing a frame gets, as a parenthesis after its size (empty without any).
pub(crate) fn anti_aliasing(samples: u32, view: &umbra::plan::View) -> String {
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

pub(crate) fn bench(a: BenchArgs) -> anyhow::Result<()> {
    let scene = load_scene(a.scene.as_ref(), &a.view)?;
    let mut base = make_view(&scene, &a.view)?;
    let ctx = offscreen_context(false, a.device.clone())?;
    let mut renderer = Renderer::with_options(&ctx, &scene, &scene_options(&a.view))?;
    crate::app::cli::warn_msaa(&a.view, renderer.samples());
    crate::app::cli::apply_budget(&scene, &mut base, &a.view, &mut renderer)?;
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
