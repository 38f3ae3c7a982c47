//! Sample-distribution fitting (`ShadowSettings::depth_fit`, SDSM) on lavapipe, validation on:
//! from eye height in front of a long wall on a 2 km ground, the camera sees depths of 3–15 m,
//! but the boxes in view (the ground's) reach a kilometre. Fitted to the boxes, the sun's
//! cascades spread their texels over that kilometre; fitted to the depths seen, every texel lies
//! within the 15 m. The shadows of a post and a crate are judged against the ray-cast reference.
//! Also here (it needs the reference too): misclassification along view depth in the town has
//! no spike at the cascade splits.

use crate::common::*;
use glam::{Mat4, Vec3};
use umbra::plan::View;
use umbra::render::Renderer;
use umbra::scene::built::shapes::{add_object, colored, cuboid};
use umbra::scene::{Camera, Light, Scene};
use umbra_lab::reference::{misclassified_by_depth, ReferenceScene};
use umbra_lab::score;

const W: u32 = 320;
const H: u32 = 180;

fn yard() -> Scene {
    let mut s = ground_scene(2000.0, "wall yard");
    for (name, half, at) in [
        (
            "wall",
            Vec3::new(60.0, 4.0, 0.25),
            Vec3::new(0.0, 4.0, -15.0),
        ),
        (
            "post",
            Vec3::new(0.06, 1.0, 0.06),
            Vec3::new(-1.0, 1.0, -6.0),
        ),
        (
            "crate",
            Vec3::new(0.3, 0.25, 0.3),
            Vec3::new(1.5, 0.25, -8.0),
        ),
    ] {
        add_object(
            &mut s,
            name,
            cuboid(half),
            colored(Vec3::new(0.6, 0.45, 0.3), 0.7),
            Mat4::from_translation(at),
        );
    }
    // 30° above the horizon, from behind the camera: shadows fall away from it, towards the wall.
    s.lights
        .push(Light::sun(Vec3::new(0.3, -0.5, -0.81).normalize(), 2.0));
    s
}

fn view(depth_fit: bool, cascades: u32) -> View {
    let cam = Camera::look_at(
        Vec3::new(0.0, 1.7, 0.0),
        Vec3::new(0.0, 1.2, -15.0),
        50f32.to_radians(),
        0.05,
    );
    let mut v = View::new(cam);
    v.shadow.depth_fit = depth_fit;
    v.shadow.cascades = cascades;
    v
}

struct Fitted {
    interior_misclassified: f64,
    misclassified: f64,
    /// World size of a texel of the nearest cascade.
    texel: f32,
    /// Where each cascade but the last ends (view depth).
    splits: Vec<f32>,
    cascades: usize,
}

fn fitted(depth_fit: bool, cascades: u32) -> Fitted {
    let ctx = context();
    let scene = yard();
    let mut r = Renderer::new(&ctx, &scene).unwrap();
    let reference = ReferenceScene::new(&scene);
    let s = score(
        &mut r,
        &reference,
        &view(depth_fit, cascades),
        (W, H),
        &mut None,
    )
    .unwrap();
    let views = &s.lit.plan.shadow_views;
    let splits = views[..views.len() - 1].iter().map(|v| v.far).collect();
    drop(r);
    assert_validation_clean(&ctx);
    save(
        &s.lit.image,
        if depth_fit {
            "depth_fit_sdsm.png"
        } else {
            "depth_fit_boxes.png"
        },
    );
    Fitted {
        interior_misclassified: s.metrics.interior_misclassified,
        misclassified: s.metrics.misclassified,
        texel: views[0].texel_world,
        splits,
        cascades: views.len(),
    }
}

#[test]
fn cascades_fitted_to_the_depths_seen_spend_their_texels_there() {
    let boxes = fitted(false, 0);
    let sdsm = fitted(true, 0);
    for (name, f) in [("boxes", &boxes), ("depths seen", &sdsm)] {
        eprintln!(
            "{name}: {} cascades split at {:.1?} m, nearest texel {:.4} m, misclassified {:.4} % \
             (interior {:.4} %)",
            f.cascades,
            f.splits,
            f.texel,
            f.misclassified * 100.0,
            f.interior_misclassified * 100.0
        );
    }
    // Measured: the boxes reach 1 km, so 4 cascades with 3.1 cm texels nearest; the depths seen
    // (3–15 m) fit in one map of 1.2 cm texels, a quarter of the layers.
    assert!(
        sdsm.texel < 0.5 * boxes.texel,
        "{} vs {}",
        sdsm.texel,
        boxes.texel
    );
    assert!(sdsm.cascades < boxes.cascades);
    assert!(sdsm.splits.iter().all(|&d| d < 15.2), "{:?}", sdsm.splits);
    assert!(
        sdsm.misclassified <= boxes.misclassified,
        "{} vs {}",
        sdsm.misclassified,
        boxes.misclassified
    );
}

#[test]
fn four_cascades_fitted_to_the_depths_seen_split_within_them() {
    let boxes = fitted(false, 4);
    let sdsm = fitted(true, 4);
    eprintln!(
        "4 cascades: boxes split at {:.1?} m (nearest texel {:.4} m, misclassified {:.4} %), \
         depths seen at {:.1?} m ({:.4} m, {:.4} %)",
        boxes.splits,
        boxes.texel,
        boxes.misclassified * 100.0,
        sdsm.splits,
        sdsm.texel,
        sdsm.misclassified * 100.0
    );
    assert!(sdsm.splits.iter().all(|&d| d < 15.2), "{:?}", sdsm.splits);
    assert!(
        sdsm.texel < 0.5 * boxes.texel,
        "{} vs {}",
        sdsm.texel,
        boxes.texel
    );
}

/// Boxes every 30 % farther along the view, 4 m to 270 m, each 8 % of its distance across (so
/// each spans about the same pixels), alternating sides: shadow edges at every view depth, the
/// cascade splits included, under a sun from the side 30° high.
fn ladder() -> Scene {
    let mut s = ground_scene(2000.0, "ladder");
    for k in 0..17 {
        let d = 4.0 * 1.3f32.powi(k);
        let half = 0.04 * d;
        let side = if k % 2 == 0 { 1.0 } else { -1.0 };
        add_object(
            &mut s,
            &format!("box {k}"),
            cuboid(Vec3::splat(half)),
            colored(Vec3::new(0.6, 0.45, 0.3), 0.7),
            Mat4::from_translation(Vec3::new(side * (0.12 * d + 0.5), half, -d)),
        );
    }
    s.lights
        .push(Light::sun(Vec3::new(-0.8, -0.55, 0.25).normalize(), 2.0));
    s
}

#[test]
fn misclassification_along_depth_has_no_spike_at_cascade_splits() {
    let ctx = context();
    let scene = ladder();
    let mut r = Renderer::new(&ctx, &scene).unwrap();
    let reference = ReferenceScene::new(&scene);
    let cam = Camera::look_at(
        Vec3::new(0.0, 12.0, 6.0),
        Vec3::new(0.0, 0.0, -60.0),
        50f32.to_radians(),
        0.05,
    );
    let mut v = View::new(cam);
    v.shadow.cascades = 4;
    let (w, h) = (640, 360);
    let mut exact = None;
    let s = score(&mut r, &reference, &v, (w, h), &mut exact).unwrap();
    let exact = exact.unwrap();
    save(&s.lit.image, "ladder_cascades_4.png");
    drop(r);
    assert_validation_clean(&ctx);
    let views = s.lit.plan.primary_views();
    assert_eq!(views.len(), 4);
    let splits: Vec<f32> = views[..3].iter().map(|v| v.far).collect();
    let bins = misclassified_by_depth(&s.classified, &exact, &s.lit.plan, 24);
    let overall = s.metrics.misclassified;
    let mut worst = 0.0f64;
    let mut at_splits = (0usize, 0usize);
    for &d in &splits {
        // The bin holding the split and its neighbours.
        let k = bins.iter().position(|b| b.near <= d && d < b.far).unwrap();
        for b in &bins[k.saturating_sub(1)..(k + 2).min(bins.len())] {
            worst = worst.max(b.fraction());
            at_splits.0 += b.judged;
            at_splits.1 += b.wrong;
        }
    }
    eprintln!(
        "ladder, 640×360, 4 cascades: splits {splits:.1?} m; overall misclassified {:.4} %, worst \
         bin at a split {:.4} % ({} of {} judged there); bins (near m, judged, wrong): {:?}",
        overall * 100.0,
        worst * 100.0,
        at_splits.1,
        at_splits.0,
        bins.iter()
            .map(|b| (b.near.round(), b.judged, b.wrong))
            .collect::<Vec<_>>()
    );
    assert!(overall < 0.002, "{overall}");
    // No spike: the pixels around the splits are misclassified no more often than the rest.
    // Measured 8 of 32,833 (0.024 %) against 0.022 % overall; the worst single bin there, 3 of
    // 6,839, is a count too small to bound on its own.
    let near_splits = at_splits.1 as f64 / at_splits.0 as f64;
    assert!(at_splits.0 > 20_000, "{at_splits:?}");
    assert!(near_splits <= 2.0 * overall, "{near_splits} vs {overall}");
}
