//! Shadows at every scale, judged by an analytic truth this file computes on its own: a box town
//! (a 2 km ground, twelve buildings out to a kilometre, a bench, a lamp post and a 2 cm awning
//! within 6 m of a camera at eye height) built at scales 0.001, 1 and 1,000, each pixel's
//! primary and shadow ray intersected with the boxes in f64 (slab tests; a ray leaving a box's
//! face towards the light cannot meet that box again, so no offset at all). Shadow rays that
//! start off their surface by a fraction of the scene's size move near outlines with the size
//! of the scene; by a fraction of the surface's own coordinates, they do not. The maps, the exact
//! method and the CPU reference are each scored against the truth at every scale (lavapipe,
//! validation on).

use crate::common::*;
use glam::{DVec3, Mat4, Vec3};
use umbra::plan::{ShadowMethod, View, ViewMode};
use umbra::render::Renderer;
use umbra::scene::built::shapes::{add_object, colored, cuboid, plane};
use umbra::scene::built::synthetic::{town_boxes, town_sun};
use umbra::scene::{Camera, Light, Scene};
use umbra_lab::reference::{classify, PixelClass, ReferenceFrame, ReferenceScene};

const W: u32 = 640;
const H: u32 = 360;
const FOV_Y_DEGREES: f32 = 60.0;
/// Half the ground's side, in metres at scale 1.
const GROUND_HALF: f64 = 1000.0;

/// The town's boxes at scale 1 as (min, max): the synthetic town's bench and buildings, a lamp
/// post 12 cm square and 4 m tall, and an awning 2 cm thick 2.6 m above the street.
fn boxes() -> Vec<(Vec3, Vec3)> {
    let mut b: Vec<(Vec3, Vec3)> = town_boxes()
        .into_iter()
        .map(|(c, h)| {
            (
                c - Vec3::new(h.x, 0.0, h.z),
                c + Vec3::new(h.x, 2.0 * h.y, h.z),
            )
        })
        .collect();
    b.push((Vec3::new(-2.06, 0.0, -4.06), Vec3::new(-1.94, 4.0, -3.94)));
    b.push((Vec3::new(1.0, 2.6, -6.0), Vec3::new(4.0, 2.62, -4.0)));
    b
}

/// The town at `scale`: the ground, the boxes and the sun; the camera 1.7 m above the street
/// looking 9 m down it.
fn town(scale: f32) -> (Scene, Camera) {
    let mut s = Scene {
        name: format!("box town ×{scale}"),
        ..Default::default()
    };
    add_object(
        &mut s,
        "ground",
        plane(2.0 * GROUND_HALF as f32 * scale, 1.0),
        colored(Vec3::splat(0.8), 1.0),
        Mat4::IDENTITY,
    );
    for (i, (lo, hi)) in boxes().into_iter().enumerate() {
        let (lo, hi) = (lo * scale, hi * scale);
        add_object(
            &mut s,
            &format!("box {i}"),
            cuboid((hi - lo) * 0.5),
            colored(Vec3::new(0.7, 0.3, 0.2), 1.0),
            Mat4::from_translation((lo + hi) * 0.5),
        );
    }
    s.lights.push(Light::sun(town_sun(), 2.0));
    let camera = Camera::look_at(
        Vec3::new(0.0, 1.7, 0.0) * scale,
        Vec3::new(0.0, 0.0, -9.0) * scale,
        FOV_Y_DEGREES.to_radians(),
        0.1 * scale,
    );
    (s, camera)
}

/// Where a ray (f64) from `o` along `d` enters box (`lo`, `hi`) at t > 0: the parameter and the
/// face's outward normal, or None.
fn slab(o: DVec3, d: DVec3, lo: DVec3, hi: DVec3) -> Option<(f64, DVec3)> {
    let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
    let mut normal = DVec3::ZERO;
    for a in 0..3 {
        if d[a] == 0.0 {
            if o[a] < lo[a] || o[a] > hi[a] {
                return None;
            }
            continue;
        }
        let (ta, tb) = ((lo[a] - o[a]) / d[a], (hi[a] - o[a]) / d[a]);
        let (near, far) = (ta.min(tb), ta.max(tb));
        if near > t0 {
            t0 = near;
            normal = DVec3::ZERO;
            normal[a] = -d[a].signum();
        }
        t1 = t1.min(far);
        if t0 > t1 {
            return None;
        }
    }
    (t0 > 0.0).then_some((t0, normal))
}

/// The analytic truth at `scale`: per pixel, whether the sun reaches the surface seen (None
/// where the ray meets nothing) and its distance.
fn truth(scale: f64) -> (Vec<Option<bool>>, Vec<f32>) {
    let boxes: Vec<(DVec3, DVec3)> = boxes()
        .into_iter()
        .map(|(lo, hi)| {
            // The f32 corners the renderer draws: centre ± half extent, each rounded to f32.
            let s = scale as f32;
            let (c, h) = ((lo + hi) * s * 0.5, (hi - lo) * s * 0.5);
            (c.as_dvec3() - h.as_dvec3(), c.as_dvec3() + h.as_dvec3())
        })
        .collect();
    let eye = DVec3::new(0.0, 1.7, 0.0) * scale;
    let forward = (DVec3::new(0.0, 0.0, -9.0) * scale - eye).normalize();
    let right = forward.cross(DVec3::Y).normalize();
    let up = right.cross(forward);
    let tan = ((FOV_Y_DEGREES as f64).to_radians() * 0.5).tan();
    let aspect = W as f64 / H as f64;
    let to_sun = -town_sun().as_dvec3().normalize();
    let ground = GROUND_HALF * scale;
    let mut vis = Vec::with_capacity((W * H) as usize);
    let mut dist = Vec::with_capacity((W * H) as usize);
    for y in 0..H {
        for x in 0..W {
            let nx = (x as f64 + 0.5) / W as f64 * 2.0 - 1.0;
            let ny = 1.0 - (y as f64 + 0.5) / H as f64 * 2.0;
            let d = (forward + right * (nx * tan * aspect) + up * (ny * tan)).normalize();
            // The nearest of the ground and the boxes: (t, normal, box index).
            let mut hit: Option<(f64, DVec3, Option<usize>)> = None;
            if d.y < 0.0 {
                let t = -eye.y / d.y;
                let p = eye + d * t;
                if p.x.abs() <= ground && p.z.abs() <= ground {
                    hit = Some((t, DVec3::Y, None));
                }
            }
            for (i, &(lo, hi)) in boxes.iter().enumerate() {
                if let Some((t, n)) = slab(eye, d, lo, hi) {
                    if hit.is_none_or(|h| t < h.0) {
                        hit = Some((t, n, Some(i)));
                    }
                }
            }
            let Some((t, n, own)) = hit else {
                vis.push(None);
                dist.push(f32::INFINITY);
                continue;
            };
            let p = eye + d * t;
            let lit = n.dot(to_sun) > 0.0
                && boxes
                    .iter()
                    .enumerate()
                    .all(|(i, &(lo, hi))| Some(i) == own || slab(p, to_sun, lo, hi).is_none());
            vis.push(Some(lit));
            dist.push(t as f32);
        }
    }
    (vis, dist)
}

/// Misclassified fractions of the judged pixels (all, and away from edges) and how many.
#[derive(Clone, Copy, Debug)]
struct Score {
    all: f64,
    interior: f64,
    judged: usize,
}

fn score(class: &[PixelClass], edge: &[bool]) -> Score {
    let (mut n, mut wrong, mut ni, mut wi) = (0usize, 0usize, 0usize, 0usize);
    for (k, &e) in class.iter().zip(edge) {
        if *k == PixelClass::Unjudged {
            continue;
        }
        let w = *k != PixelClass::Correct;
        n += 1;
        wrong += w as usize;
        if !e {
            ni += 1;
            wi += w as usize;
        }
    }
    Score {
        all: wrong as f64 / n.max(1) as f64,
        interior: wi as f64 / ni.max(1) as f64,
        judged: n,
    }
}

/// The truth as a reference frame (`classify` reads its visibility and distances).
fn truth_frame(scale: f64) -> ReferenceFrame {
    let (visibility, distance) = truth(scale);
    ReferenceFrame {
        width: W,
        height: H,
        coverage: visibility
            .iter()
            .map(|v| v.map(|l| l as u8 as f32))
            .collect(),
        visibility,
        distance,
        image: image::RgbaImage::new(W, H),
        curved: vec![false; (W * H) as usize],
        incidence: vec![1.0; (W * H) as usize],
        coincident: vec![false; (W * H) as usize],
    }
}

/// One scale's scores against the truth: the maps, the exact method, the hybrid one and the CPU
/// reference.
fn measure(scale: f32) -> [Score; 4] {
    let (scene, camera) = town(scale);
    let truth = truth_frame(scale as f64);
    let ctx = context();
    let mut r = Renderer::new(&ctx, &scene).unwrap();
    r.set_read_depth(true);
    let mut view = View::new(camera);
    view.mode = ViewMode::Shadow;
    let mut gpu = Vec::new();
    for method in [ShadowMethod::Map, ShadowMethod::Exact, ShadowMethod::Hybrid] {
        view.shadow.method = method;
        let f = r.render(&view, W, H).unwrap();
        assert_eq!(f.plan.exact_shadows(), method.traces());
        assert_eq!(f.plan.hybrid_shadows(), method == ShadowMethod::Hybrid);
        let c = classify(&f.image, f.depth.as_deref().unwrap(), &f.plan, &truth);
        assert!(
            c.coverage_mismatch < 200,
            "×{scale} {method:?}: {} pixels where the renderer and the truth see different \
             surfaces",
            c.coverage_mismatch
        );
        gpu.push((score(&c.class, &c.edge), c.edge, f.plan));
    }
    drop(r);
    assert_validation_clean(&ctx);
    // The CPU reference, judged where it sees the truth's surface (distances within 1 %), as
    // `classify` judges the GPU.
    let (edge, plan) = (&gpu[1].1, &gpu[1].2);
    let reference = ReferenceScene::new(&scene).render(plan, W, H, plan.ambient);
    let class: Vec<PixelClass> = (0..(W * H) as usize)
        .map(|i| match (truth.visibility[i], reference.visibility[i]) {
            (Some(t), Some(r))
                if (reference.distance[i] - truth.distance[i]).abs()
                    <= 0.01 * truth.distance[i] =>
            {
                match (t, r) {
                    (true, false) => PixelClass::FalseShadow,
                    (false, true) => PixelClass::FalseLight,
                    _ => PixelClass::Correct,
                }
            }
            _ => PixelClass::Unjudged,
        })
        .collect();
    [gpu[0].0, gpu[1].0, gpu[2].0, score(&class, edge)]
}

/// The scale table: maps, exact and the reference against the analytic truth at 0.001, 1 and
/// 1,000 (lavapipe, 640×360, 2048² map, 169,217 pixels judged). Measured: exact 0, 0.0018 % and
/// 0 (3 pixels at most), the reference 0.0006–0.0012 % (1–2 pixels), none away from edges; with
/// the offset before (2·10⁻⁵ of the scene's diagonal, 5.7 cm at scale 1) both misclassified
/// 0.17 % at every scale (0.0013 % away from edges). The maps: 0.37 %, 0.17 % and 0.32 %, all at
/// outlines.
#[test]
fn shadows_are_the_same_at_every_scale() {
    let scales = [0.001f32, 1.0, 1000.0];
    let rows: Vec<[Score; 4]> = scales.iter().map(|&s| measure(s)).collect();
    println!("scale   | method    | misclassified | away from edges | judged");
    for (s, row) in scales.iter().zip(&rows) {
        for (name, sc) in ["map", "exact", "hybrid", "reference"].iter().zip(row) {
            println!(
                "{s:>7} | {name:<9} | {:>12.4}% | {:>14.4}% | {}",
                sc.all * 100.0,
                sc.interior * 100.0,
                sc.judged
            );
        }
    }
    for (s, [map, exact, hybrid, reference]) in scales.iter().zip(&rows) {
        assert!(
            exact.all <= 1e-4 && hybrid.all <= 1e-4 && reference.all <= 1e-4,
            "×{s}: exact {:.4}%, hybrid {:.4}%, reference {:.4}% of pixels disagree with the \
             truth (bound 0.01 %)",
            exact.all * 100.0,
            hybrid.all * 100.0,
            reference.all * 100.0
        );
        assert!(exact.judged > 150_000, "×{s}: only {} judged", exact.judged);
        // The maps err only at outlines, by as much at every scale: which pixels their texels'
        // stairs catch moves with the grid's phase (the fitted extents snap to powers of two).
        assert!(
            map.interior <= 1e-5 && map.all <= 5e-3,
            "×{s}: the maps misclassify {:.4}% ({:.4}% away from edges)",
            map.all * 100.0,
            map.interior * 100.0
        );
    }
}
