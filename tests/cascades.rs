//! Cascaded shadow maps on a scene as large as a town, seen from eye height (lavapipe,
//! validation on; `scene::built::synthetic::town_scene`): a 2 km ground with buildings up to a kilometre
//! away and a bench-sized box six metres in front of the camera. One map fitted to the view spends its texels over a kilometre of
//! depth and loses the near shadow; four cascades keep it. Judged against exact visibility: every
//! ground pixel's ray towards the sun against the boxes, away from shadow edges (EDGE_TEXELS
//! texels of the cascade that shades the pixel, or one pixel).

use crate::common::*;
use glam::{Mat4, Vec3};
use umbra::math::ray::{ray_aabb, Ray};
use umbra::math::Aabb;
use umbra::plan::{View, ViewMode};
use umbra::render::{RenderedFrame, Renderer};
use umbra::scene::built::synthetic::{town_boxes, town_scene, town_sun};
use umbra::scene::Camera;

const EDGE_TEXELS: f32 = 3.0;
const W: u32 = 320;
const H: u32 = 180;
/// Ground pixels nearer than this (metres) are "near".
const NEAR: f32 = 30.0;

fn sun() -> Vec3 {
    town_sun()
}

fn aabbs() -> Vec<Aabb> {
    town_boxes()
        .iter()
        .map(|&(c, h)| {
            Aabb::new(
                c - Vec3::new(h.x, 0.0, h.z),
                c + Vec3::new(h.x, 2.0 * h.y, h.z),
            )
        })
        .collect()
}

fn exact_visible(boxes: &[Aabb], g: Vec3) -> bool {
    let r = Ray::new(g, -sun());
    boxes
        .iter()
        .all(|b| ray_aabb(&r, b, 1e-4, f32::INFINITY).is_none())
}

/// The ground point seen through pixel (x, y), or None for sky and boxes.
fn ground_point(m: &Mat4, boxes: &[Aabb], x: u32, y: u32) -> Option<Vec3> {
    let (o, d) = pixel_ray(m, x, y, W, H);
    let d = d.normalize();
    if d.y >= -1e-6 {
        return None;
    }
    let t = -o.y / d.y;
    if boxes
        .iter()
        .any(|b| ray_aabb(&Ray::new(o, d), b, 0.0, t).is_some())
    {
        return None;
    }
    let g = o + d * t;
    // The ground ends 1 km out.
    (g.x.abs() < 999.0 && g.z.abs() < 999.0).then_some(g)
}

#[derive(Debug, Default)]
struct Errors {
    near_judged: usize,
    near_shadowed: usize,
    near_wrong: usize,
    far_judged: usize,
    far_shadowed: usize,
    far_wrong: usize,
}

/// Errors of frame `f`; the unjudged edge bands come from `bands` (the same plan for every
/// method compared, so a coarse method is not excused by its own coarse texels).
fn judge(f: &RenderedFrame, bands: &RenderedFrame, cam: &Camera) -> Errors {
    let m = f.plan.clip_from_scene();
    let boxes = aabbs();
    let eye = cam.position();
    let forward = (cam.view_from_world().inverse()).transform_vector3(-Vec3::Z);
    let mut e = Errors::default();
    for y in 1..H - 1 {
        for x in 1..W - 1 {
            let Some(g) = ground_point(&m, &boxes, x, y) else {
                continue;
            };
            let vis = exact_visible(&boxes, g);
            // The coarsest view that may shade this depth (the next one inside a blend band).
            let depth = (g - eye).dot(forward);
            let views = &bands.plan.shadow_views;
            let c = views
                .iter()
                .position(|v| depth <= v.far)
                .unwrap_or(views.len() - 1);
            let c = if depth > views[c].blend {
                (c + 1).min(views.len() - 1)
            } else {
                c
            };
            let band = EDGE_TEXELS * views[c].texel_world;
            let mut edge = [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)]
                .iter()
                .any(|&(dx, dz)| {
                    exact_visible(&boxes, g + Vec3::new(dx * band, 0.0, dz * band)) != vis
                });
            for (nx, ny) in [(x - 1, y), (x + 1, y), (x, y - 1), (x, y + 1)] {
                match ground_point(&m, &boxes, nx, ny) {
                    Some(n) if exact_visible(&boxes, n) == vis => {}
                    _ => edge = true,
                }
            }
            if edge {
                continue;
            }
            let lit = f.image.get_pixel(x, y)[0] >= 128;
            if (g - eye).length() < NEAR {
                e.near_judged += 1;
                e.near_shadowed += usize::from(!vis);
                e.near_wrong += usize::from(lit != vis);
            } else {
                e.far_judged += 1;
                e.far_shadowed += usize::from(!vis);
                e.far_wrong += usize::from(lit != vis);
            }
        }
    }
    e
}

/// Renders the town from `cam` with one map and with four cascades (shadow view), saves both
/// (and the lit images) and judges both with the cascades' edge bands.
fn one_and_four(r: &mut Renderer, cam: Camera, name: &str) -> Vec<Errors> {
    let mut frames = Vec::new();
    for cascades in [1, 4] {
        let mut view = View::new(cam);
        view.mode = ViewMode::Shadow;
        view.shadow.cascades = cascades;
        let f = r.render(&view, W, H).unwrap();
        save(&f.image, &format!("town_{name}_cascades_{cascades}.png"));
        let mut lit = View::new(cam);
        lit.shadow.cascades = cascades;
        let img = r.render(&lit, W, H).unwrap().image;
        save(&img, &format!("town_{name}_lit_cascades_{cascades}.png"));
        assert_eq!(f.plan.shadow_views.len(), cascades as usize);
        frames.push(f);
    }
    let results: Vec<Errors> = frames.iter().map(|f| judge(f, &frames[1], &cam)).collect();
    for (f, e) in frames.iter().zip(&results) {
        eprintln!(
            "{name}, {} view(s): nearest texel {:.3} m; {e:?}",
            f.plan.shadow_views.len(),
            f.plan.shadow_views[0].texel_world
        );
    }
    results
}

#[test]
fn cascades_keep_near_shadows_in_a_town() {
    let ctx = context();
    let scene = town_scene();
    let mut r = Renderer::new(&ctx, &scene).unwrap();
    // From eye height: the bench's shadow 5–7 m away.
    let street = one_and_four(&mut r, scene.cameras[0], "street");
    let (one, four) = (&street[0], &street[1]);
    assert!(four.near_shadowed > 250, "{four:?}");
    // Measured: one map 295 of 295 near shadow pixels lit (its texel is 0.71 m); four cascades 0.
    assert!(
        one.near_wrong * 10 > one.near_shadowed * 9,
        "one map: {one:?}"
    );
    assert!(four.near_wrong <= 3, "four cascades: {four:?}");
    // From a roof, looking 150 m down the street: the buildings' shadows fall in every cascade.
    let over = one_and_four(&mut r, scene.cameras[1], "roof");
    // Measured: 139 judged shadow pixels (the rest lie in the coarser cascades' edge bands),
    // 0 wrong with four cascades, 1 with one map.
    let four = &over[1];
    assert!(four.far_shadowed > 110, "{four:?}");
    assert!(four.far_wrong <= 3, "four cascades: {four:?}");
    // The automatic count (the default) at 1280×720: four from the street (one map's texel is
    // ~180 pixel footprints at the nearest ground), two from the roof (~15); at 320×180 the
    // roof's pixels are four times larger and one map does.
    for (cam, (w, h), want) in [
        (scene.cameras[0], (1280, 720), 4),
        (scene.cameras[1], (1280, 720), 2),
        (scene.cameras[1], (W, H), 1),
    ] {
        let f = r.render(&View::new(cam), w, h).unwrap();
        assert_eq!(f.plan.shadow_views.len(), want, "{w}x{h}");
    }
    drop(r);
    assert_validation_clean(&ctx);
}
