//! The stability suite on its built-in scene (quick mode, lavapipe, validation on): the issue's
//! thresholds hold at the defaults, and the probes report failure when the method is broken on
//! purpose (8× the bias: a contact gap; no snapping: shimmer, in the first test). And the foliage
//! probe: leaf shadows shimmer along the suite's flythrough with maps, not with exact shadows.

use crate::common::*;
use umbra::plan::ScenePlanner;
use umbra::plan::{ShadowMethod, ShadowSettings, View};
use umbra::render::Renderer;
use umbra::scene::built::foliage::foliage_scene;
use umbra::scene::built::synthetic::{stability_scene, STABILITY_WALL_HALF};
use umbra::scene::AlphaMode;
use umbra_lab::analysis::stability::light::{classify_view_at, contact_gaps};
use umbra_lab::analysis::stability::report::{self, SHIMMER_BOUND};
use umbra_lab::analysis::stability::shimmer::{camera_path, shimmer, Method};
use umbra_lab::analysis::stability::StabilityOptions;
use umbra_lab::reference::ReferenceScene;

const SIZE: (u32, u32) = (640, 360);

#[test]
fn builtin_scene_meets_the_thresholds_at_the_defaults() {
    let ctx = context();
    let scene = stability_scene();
    let view = View::new(scene.cameras[0]);
    let r = report::run(
        &ctx,
        &scene,
        &view,
        &Default::default(),
        &StabilityOptions {
            size: SIZE,
            quick: true,
            animation: None,
        },
        Some(STABILITY_WALL_HALF),
        &mut |_| {},
    )
    .unwrap();
    for v in &r.verdicts {
        println!("{:?} {}: {}", v.pass, v.criterion, v.measured);
    }
    // Acne: 0 planar pixels from 1° (measured 0 of 2.35 M judged), 0 curved from 5° (0 of 29 k).
    let defaults = r.light_angle.iter().filter(|a| a.bias_scale == 1.0);
    let mut planar = 0;
    for a in defaults {
        if a.elevation_deg >= 1.0 {
            assert_eq!(
                a.counts.acne_planar, 0,
                "planar acne at {}°",
                a.elevation_deg
            );
            planar += a.counts.planar;
        }
        if a.elevation_deg >= 5.0 {
            assert_eq!(
                a.counts.acne_curved, 0,
                "curved acne at {}°",
                a.elevation_deg
            );
        }
    }
    assert!(planar > 1_000_000, "{planar} planar pixels judged");
    // Contact: the shadow touches the thin wall's base (measured gap 0 texels at 5–80°).
    assert!(!r.contact.is_empty());
    for c in &r.contact {
        let g = c.gap_texels_max.expect("base points seen");
        assert!(
            c.points >= 100,
            "{} points at {}°",
            c.points,
            c.elevation_deg
        );
        assert!(g <= 2.0, "gap {g} texels at {}°", c.elevation_deg);
    }
    // Shimmer: snapped single map 1.9e-7 flipped per frame (2 points in 59 frames; 9.2e-8 with
    // D32, 1.9e-6 with D16 before its depth lattice held still); 4 snapped cascades 9.9e-5
    // fitted afresh each frame, 5.0e-5 held (the dithered blend bands move with the camera);
    // unsnapped 1.0e-3 and 5.8e-4.
    for s in &r.shimmer {
        if s.snapped {
            assert!(
                s.mean_fraction <= SHIMMER_BOUND,
                "{}: {:e}",
                s.method,
                s.mean_fraction
            );
        } else {
            let twin = r
                .shimmer
                .iter()
                .find(|t| t.snapped && !t.held && t.cascades == s.cascades && t.fit == s.fit)
                .unwrap();
            assert!(
                s.mean_fraction >= 2.0 * twin.mean_fraction,
                "{}: {:e} vs {:e}",
                s.method,
                s.mean_fraction,
                twin.mean_fraction
            );
        }
    }
    let single = r
        .shimmer
        .iter()
        .find(|s| s.method == "single map, snapped")
        .unwrap();
    assert!(single.mean_fraction <= 1e-6, "{:e}", single.mean_fraction);
    // What the steadier fits pay: the bounding-sphere map's texel is coarser than the fit to the
    // receivers in view (measured 1.09× on this path's first quarter), the powers-of-2 ladder's
    // no finer.
    let method = |m: &str| r.shimmer.iter().find(|s| s.method == m).unwrap();
    let sphere = method("single map, sphere fit");
    assert!(
        sphere.mean_texel > 1.05 * single.mean_texel,
        "{:e} vs {:e}",
        sphere.mean_texel,
        single.mean_texel
    );
    assert!(method("single map, snapped to powers of 2").mean_texel >= single.mean_texel);
    // Held across frames (as the viewer renders), the cascades' extents and splits step by
    // doublings: measured 5.2e-5 against 9.9e-5 fitted afresh every frame.
    let held = method("4 cascades, snapped, held").mean_fraction;
    let fresh = method("4 cascades, snapped").mean_fraction;
    assert!(held < 0.75 * fresh, "{held:e} vs {fresh:e}");
    // Precision: 10⁴ and 10⁶ units out stay with the origin's misclassification (measured
    // 0.95× at both, against 5.1× at 10⁶ before transforms were rebased to the render origin):
    // the world's f32 step there (6.25 cm) is past the 1.4 cm texel, the GPU's is not.
    let at = |o: f64| {
        r.precision
            .iter()
            .find(|p| p.offset == o && p.scale == 1.0)
            .unwrap()
    };
    for o in [1e4, 1e6] {
        assert!(
            at(o).ratio_to_origin <= 1.1,
            "{o}: {}",
            at(o).ratio_to_origin
        );
    }
    assert!(at(1e6).position_step > at(1e6).texel_world);
    assert!(at(1e6).gpu_position_step < 1e-3 * at(1e6).texel_world);
    for p in r.precision.iter().filter(|p| p.offset == 0.0) {
        assert!(
            p.ratio_to_origin <= 1.5,
            "scale {}: {}×",
            p.scale,
            p.ratio_to_origin
        );
    }
    // In motion (a box crossing the scene, then the sun's arc), exact and hybrid shadows flip
    // no still point away from edges, and at edges far fewer than the maps held across frames do.
    let hybrid = r.motion.iter().filter(|s| s.method == "hybrid").count();
    assert_eq!(hybrid, 2, "both probes fly hybrid shadows");
    for s in r
        .motion
        .iter()
        .filter(|s| s.method == "exact" || s.method == "hybrid")
    {
        let maps = r
            .motion
            .iter()
            .find(|m| m.probe == s.probe && m.method == "defaults, held")
            .unwrap();
        println!(
            "{}: {} {:e} ({:e} away from edges), maps held {:e} ({:e})",
            s.probe,
            s.method,
            s.mean_fraction,
            s.mean_interior_fraction,
            maps.mean_fraction,
            maps.mean_interior_fraction
        );
        // Measured: 0 for the moving box; 2 points of 4.7 million on the sun's arc (one pair of
        // frames: false shadow on the torus's lower rim where the sun grazes it, which `compare`
        // counts as misclassified in that frame).
        let flipped: usize = s.interior.iter().map(|&(_, f)| f).sum();
        assert!(
            s.interior.iter().all(|&(n, _)| n > 10_000) && flipped <= 3,
            "{} {}: {:?}",
            s.probe,
            s.method,
            s.interior
        );
        assert!(
            s.mean_fraction <= 0.1 * maps.mean_fraction,
            "{}: {} {:e} against the maps' {:e}",
            s.probe,
            s.method,
            s.mean_fraction,
            maps.mean_fraction
        );
    }
    // Degenerate cases: all pass, with validation messages counted (0).
    for d in &r.degenerate {
        assert!(d.ok, "{}: {d:?}", d.case);
        assert_eq!(d.validation_messages, Some(0), "{}", d.case);
    }
    // The files: JSON with the schema, every chart, the summary with its verdict table.
    let dir = std::env::temp_dir().join(format!("umbra-stability-{}", std::process::id()));
    report::write(&r, &dir).unwrap();
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("stability.json")).unwrap())
            .unwrap();
    assert_eq!(j["schema"], "umbra-stability/1");
    for name in ["light-angle", "bias", "shimmer", "precision", "scale"] {
        let png = image::open(dir.join(format!("{name}.png"))).unwrap();
        assert_eq!(png.width(), 1100);
        assert!(
            std::fs::metadata(dir.join(format!("{name}.svg")))
                .unwrap()
                .len()
                > 2000
        );
    }
    let md = std::fs::read_to_string(dir.join("stability.md")).unwrap();
    assert!(md.contains("| criterion | measured | result |"));
    // The report page: a row per verdict, each judged as the run judged it, and every chart.
    let summary = umbra_lab::report::write(&dir, None).unwrap();
    assert_eq!((summary.stabilities, summary.goldens), (1, 0));
    let page = std::fs::read_to_string(&summary.path).unwrap();
    let count = |class: &str| page.matches(&format!("<td class=\"{class}\">")).count();
    let judged = |p: Option<bool>| r.verdicts.iter().filter(|v| v.pass == p).count();
    assert_eq!(count("pass"), judged(Some(true)));
    assert_eq!(count("fail"), judged(Some(false)));
    assert_eq!(count("na"), judged(None));
    let charts = std::fs::read_dir(&dir)
        .unwrap()
        .filter(|e| e.as_ref().unwrap().path().extension().unwrap() == "png")
        .count();
    assert_eq!(page.matches("data:image/png;base64,").count(), charts);
    let _ = std::fs::remove_dir_all(&dir);
    drop(r);
    assert_validation_clean(&ctx);
}

#[test]
fn probes_fail_when_the_method_is_broken() {
    let ctx = context();
    let scene = stability_scene();
    let view = View::new(scene.cameras[0]);
    let mut renderer = Renderer::new(&ctx, &scene).unwrap();
    let reference = ReferenceScene::new(&scene);
    // The defaults at 30°: no acne (the acne classifier itself is unit-tested on hand-made
    // frames in `analysis::stability`: umbra's back-face casters and skipped flat receivers
    // leave no bias setting that makes acne here).
    let (c, _) = classify_view_at(&mut renderer, &reference, &view, 30.0, 0.0, 1.0, SIZE).unwrap();
    assert_eq!(c.acne_planar + c.acne_curved, 0, "{c:?}");
    // 8× the bias: the shadow leaves the thin wall's base (the defaults: gap 0).
    let mut biased = view.clone();
    biased.shadow.constant_bias *= 8.0;
    biased.shadow.normal_offset *= 8.0;
    let planner = ScenePlanner::new(&scene);
    let rows = contact_gaps(
        &mut renderer,
        &planner,
        &biased,
        STABILITY_WALL_HALF,
        &[15.0],
        SIZE,
        &mut || {},
    )
    .unwrap();
    let g = rows[0].gap_texels_max.unwrap();
    assert!(g > 2.0, "gap {g} texels with 8× bias");
    drop(renderer);
    assert_validation_clean(&ctx);
}

#[test]
fn leaf_shadows_shimmer_with_maps_and_hold_still_when_exact() {
    // The stability suite's flythrough of the foliage (its first 12 frames, 320×180): the
    // fraction of fixed world points whose shadow flips between consecutive frames while only
    // the camera moves.
    let scene = foliage_scene(AlphaMode::Mask(0.5));
    let ctx = context();
    let mut r = Renderer::new(&ctx, &scene).unwrap();
    r.set_read_depth(true);
    let view = View::new(scene.cameras[0]);
    let path = camera_path(&scene.cameras[0], &scene.bounds(), 60);
    let defaults = ShadowSettings::default();
    let methods = [
        Method {
            name: "defaults, held".into(),
            shadow: defaults,
            held: true,
        },
        Method {
            name: "single map, snapped".into(),
            shadow: ShadowSettings {
                cascades: 1,
                ..defaults
            },
            held: false,
        },
        Method {
            name: "exact".into(),
            shadow: ShadowSettings {
                method: ShadowMethod::Exact,
                ..defaults
            },
            held: false,
        },
    ];
    let series = shimmer(&mut r, &view, &path[..12], &methods, (320, 180), &mut || {}).unwrap();
    drop(r);
    assert_validation_clean(&ctx);
    for s in &series {
        eprintln!(
            "{}: {:.2e} of the points flip per frame (max {:.2e}, {} flips over {} pairs)",
            s.method,
            s.mean_fraction,
            s.max_fraction,
            s.flipped.iter().sum::<usize>(),
            s.flipped.len()
        );
    }
    let of = |m: &str| series.iter().find(|s| s.method == m).unwrap();
    // Exact verdicts do not depend on the fit: nothing flips (measured 0).
    assert_eq!(of("exact").flipped.iter().sum::<usize>(), 0);
    // Leaf shadows finer than a texel shimmer with maps: measured 1.58e-3 for a single snapped
    // map (171 flips, 1.7e-2 on the pair where its extent steps), 2.97e-5 for the defaults held
    // as the viewer holds them (3 flips).
    assert!(of("single map, snapped").mean_fraction > 5e-4);
    assert!(of("defaults, held").mean_fraction < of("single map, snapped").mean_fraction);
}
