//! Shadow tests on lavapipe (validation on), where geometry gives the answer: a unit box on a
//! plane, every ground pixel's exact visibility found by casting a ray towards the light.
//!
//! Tolerance: pixels whose exact visibility changes within EDGE_TEXELS shadow texels (world size
//! from the fitted frustum) or one pixel of them are the edge band and are not judged; everything
//! else must agree with the exact answer (GPU visibility thresholded at 0.5).

use crate::common::*;
use glam::{Mat4, Vec3};
use umbra::math::ray::{ray_aabb, Ray};
use umbra::math::Aabb;
use umbra::plan::{ShadowFormat, ShadowSettings, View, ViewMode};
use umbra::render::Renderer;
use umbra::scene::built::shapes::{add_object, colored, cuboid};
use umbra::scene::{Camera, Light, LightKind, Scene};

/// Width of the unjudged band around exact shadow edges, in shadow texels.
const EDGE_TEXELS: f32 = 3.0;
const W: u32 = 256;
const H: u32 = 192;

// Half extents of the caster standing on the ground at the origin, per test thread.
thread_local! {
    static CASTER_HALF: std::cell::Cell<Vec3> = const { std::cell::Cell::new(Vec3::ONE) };
    // World placement of the whole test scene (uniform scale, then translation), per test thread.
    static PLACEMENT: std::cell::Cell<(f32, Vec3)> = const { std::cell::Cell::new((1.0, Vec3::ZERO)) };
}

fn world_from_local() -> Mat4 {
    let (s, t) = PLACEMENT.with(|p| p.get());
    Mat4::from_translation(t) * Mat4::from_scale(Vec3::splat(s))
}

fn box_aabb() -> Aabb {
    let h = CASTER_HALF.with(|c| c.get());
    Aabb::new(Vec3::new(-h.x, 0.0, -h.z), Vec3::new(h.x, 2.0 * h.y, h.z))
}

fn caster_scene(light: Light, half: Vec3) -> Scene {
    CASTER_HALF.with(|c| c.set(half));
    let mut s = ground_scene(60.0, "caster on plane");
    add_object(
        &mut s,
        "caster",
        cuboid(half),
        colored(Vec3::new(0.7, 0.2, 0.1), 1.0),
        Mat4::from_translation(Vec3::Y * half.y),
    );
    s.lights.push(light);
    s
}

fn box_scene(light: Light) -> Scene {
    caster_scene(light, Vec3::ONE)
}

/// The box scene placed at `scale` and `offset` in the world (for huge, tiny and far scenes).
fn placed_box_scene(light: Light, scale: f32, offset: Vec3) -> Scene {
    let mut s = caster_scene(light, Vec3::ONE);
    PLACEMENT.with(|p| p.set((scale, offset)));
    let m = world_from_local();
    for inst in &mut s.instances {
        inst.world_from_model = m * inst.world_from_model;
    }
    s
}

/// Exact visibility of ground point `g` from the light: 1 lit, 0 blocked by the caster.
fn exact_visible(light: &Light, g: Vec3) -> bool {
    let (dir, t_max) = match light.kind {
        LightKind::Directional => (-light.direction, f32::INFINITY),
        _ => {
            let d = light.position - g;
            (d.normalize(), d.length())
        }
    };
    ray_aabb(&Ray::new(g, dir), &box_aabb(), 1e-5, t_max).is_none()
}

/// The ground point (in the scene's local frame) seen through pixel (x, y), or None when the box
/// or the sky is seen.
fn ground_point(clip_from_world: &Mat4, x: u32, y: u32) -> Option<Vec3> {
    let (o, d) = pixel_ray(clip_from_world, x, y, W, H);
    let local = world_from_local().inverse();
    let (o, d) = (
        local.transform_point3(o),
        local.transform_vector3(d).normalize(),
    );
    if d.y >= -1e-6 {
        return None;
    }
    let t = -o.y / d.y;
    if ray_aabb(&Ray::new(o, d), &box_aabb(), 0.0, t).is_some() {
        return None;
    }
    let g = o + d * t;
    (g.x.abs() < 30.0 && g.z.abs() < 30.0).then_some(g)
}

struct Judged {
    judged: usize,
    false_shadow: usize,
    false_light: usize,
    exact_shadowed: usize,
}

fn judge(
    frame: &umbra::render::RenderedFrame,
    light: &Light,
    band: f32,
) -> (Judged, image::RgbaImage) {
    let m = frame.plan.clip_from_scene();
    let mut diff = frame.image.clone();
    let mut j = Judged {
        judged: 0,
        false_shadow: 0,
        false_light: 0,
        exact_shadowed: 0,
    };
    for y in 1..H - 1 {
        for x in 1..W - 1 {
            let Some(g) = ground_point(&m, x, y) else {
                continue;
            };
            let vis = exact_visible(light, g);
            // Edge band: world offsets of `band` and the neighbouring pixels' ground points.
            let mut edge = false;
            for (dx, dz) in [
                (1.0, 0.0),
                (-1.0, 0.0),
                (0.0, 1.0),
                (0.0, -1.0),
                (0.7, 0.7),
                (-0.7, 0.7),
                (0.7, -0.7),
                (-0.7, -0.7),
            ] {
                if exact_visible(light, g + Vec3::new(dx * band, 0.0, dz * band)) != vis {
                    edge = true;
                }
            }
            for (nx, ny) in [(x - 1, y), (x + 1, y), (x, y - 1), (x, y + 1)] {
                match ground_point(&m, nx, ny) {
                    Some(n) if exact_visible(light, n) == vis => {}
                    _ => edge = true,
                }
            }
            if edge {
                continue;
            }
            j.judged += 1;
            let gpu_lit = frame.image.get_pixel(x, y)[0] >= 128;
            if !vis {
                j.exact_shadowed += 1;
            }
            if vis && !gpu_lit {
                j.false_shadow += 1;
                diff.put_pixel(x, y, image::Rgba([255, 0, 0, 255]));
            } else if !vis && gpu_lit {
                j.false_light += 1;
                diff.put_pixel(x, y, image::Rgba([0, 0, 255, 255]));
            }
        }
    }
    (j, diff)
}

fn shadow_view(camera: Camera) -> View {
    let mut v = View::new(camera);
    v.mode = ViewMode::Shadow;
    v
}

/// A camera on the shadow side of the box, looking back at it, so the shadow and the box's base
/// on that side are in view.
fn camera_on_shadow_side(light_dir: Vec3) -> Camera {
    let h = Vec3::new(light_dir.x, 0.0, light_dir.z).normalize_or(Vec3::Z);
    Camera::look_at(
        h * 8.0 + Vec3::new(2.0, 10.0, 0.0),
        h * 2.0,
        55f32.to_radians(),
        0.1,
    )
}

#[test]
fn box_shadow_matches_geometry_at_80_45_15_degrees() {
    let ctx = context();
    for elevation in [80.0f32, 45.0, 15.0] {
        let light = Light::sun(Light::sun_direction(elevation.to_radians(), 0.6), 2.0);
        let scene = box_scene(light);
        let mut r = Renderer::new(&ctx, &scene).unwrap();
        let view = shadow_view(camera_on_shadow_side(light.direction));
        let f = r.render(&view, W, H).unwrap();
        let band = EDGE_TEXELS * f.plan.texel_world();
        let (j, diff) = judge(&f, &light, band);
        save(&f.image, &format!("box_shadow_{elevation}.png"));
        save(&diff, &format!("box_shadow_{elevation}_diff.png"));
        assert!(
            j.judged > (W * H / 3) as usize,
            "too few judged pixels at {elevation}°: {}",
            j.judged
        );
        assert!(
            j.exact_shadowed > 60,
            "the shadow must be in view at {elevation}°: {}",
            j.exact_shadowed
        );
        assert_eq!(
            (j.false_shadow, j.false_light),
            (0, 0),
            "misclassified outside the {EDGE_TEXELS}-texel band at {elevation}° (of {} judged)",
            j.judged
        );
    }
    assert_validation_clean(&ctx);
}

#[test]
fn huge_tiny_and_far_scenes_match_geometry() {
    // The same box on a plane at 1 mm, 1 km and 10 km from the origin: shadows stay exact outside
    // the band (measured in the scene's own units).
    let ctx = context();
    let light = Light::sun(Light::sun_direction(35f32.to_radians(), 0.6), 2.0);
    for (scale, offset) in [
        (1e-3, Vec3::ZERO),
        (1e3, Vec3::ZERO),
        (1.0, Vec3::new(1e4, 0.0, -1e4)),
        (1e-2, Vec3::new(50.0, 3.0, 0.0)),
    ] {
        let scene = placed_box_scene(light, scale, offset);
        let mut r = Renderer::new(&ctx, &scene).unwrap();
        let local_cam = camera_on_shadow_side(light.direction);
        let m = world_from_local();
        let eye = m.transform_point3(local_cam.position());
        let target = m.transform_point3(
            local_cam.position() + local_cam.world_from_view.transform_vector3(-Vec3::Z),
        );
        let cam = Camera::look_at(eye, target, local_cam.fov_y().unwrap(), 0.1 * scale);
        let f = r.render(&shadow_view(cam), W, H).unwrap();
        let (j, diff) = judge(&f, &light, EDGE_TEXELS * f.plan.texel_world() / scale);
        save(&diff, &format!("placed_{scale}_{}_diff.png", offset.x));
        assert!(
            j.judged > (W * H / 3) as usize && j.exact_shadowed > 200,
            "scale {scale} offset {offset}: {} judged",
            j.judged
        );
        assert_eq!(
            (j.false_shadow, j.false_light),
            (0, 0),
            "scale {scale} offset {offset} (of {} judged)",
            j.judged
        );
    }
    PLACEMENT.with(|p| p.set((1.0, Vec3::ZERO)));
    assert_validation_clean(&ctx);
}

#[test]
fn d16_shadow_map_matches_geometry_too() {
    let ctx = context();
    for elevation in [60.0f32, 25.0] {
        let light = Light::sun(Light::sun_direction(elevation.to_radians(), 0.6), 2.0);
        let scene = box_scene(light);
        let mut r = Renderer::new(&ctx, &scene).unwrap();
        let mut view = shadow_view(camera_on_shadow_side(light.direction));
        view.shadow.format = ShadowFormat::D16;
        let f = r.render(&view, W, H).unwrap();
        let (j, diff) = judge(&f, &light, EDGE_TEXELS * f.plan.texel_world());
        save(&diff, &format!("box_shadow_d16_{elevation}_diff.png"));
        assert!(j.exact_shadowed > 60);
        assert_eq!(
            (j.false_shadow, j.false_light),
            (0, 0),
            "D16 at {elevation}° (of {} judged)",
            j.judged
        );
    }
    assert_validation_clean(&ctx);
}

#[test]
fn no_acne_on_a_plane_from_10_to_90_degrees() {
    let ctx = context();
    let s = ground_scene(60.0, "plane");
    let mut r = Renderer::new(&ctx, &s).unwrap();
    let cases = (10..=90)
        .step_by(10)
        .flat_map(|e| [(e, ShadowFormat::D32), (e, ShadowFormat::D16)]);
    for (elevation, depth_format) in cases {
        for azimuth in [0.0f32, 0.9] {
            let dir = Light::sun_direction((elevation as f32).to_radians(), azimuth);
            let mut view = shadow_view(Camera::look_at(
                Vec3::new(5.0, 6.0, 12.0),
                Vec3::ZERO,
                60f32.to_radians(),
                0.1,
            ));
            view.sun_direction = Some(dir);
            view.shadow.format = depth_format;
            let f = r.render(&view, W, H).unwrap();
            let m = f.plan.clip_from_scene();
            let mut ground = 0;
            let mut shadowed = 0;
            for y in 0..H {
                for x in 0..W {
                    if ground_point(&m, x, y).is_some() {
                        ground += 1;
                        if f.image.get_pixel(x, y)[0] < 255 {
                            shadowed += 1;
                        }
                    }
                }
            }
            if shadowed > 0 {
                save(&f.image, &format!("acne_{elevation}.png"));
            }
            assert!(ground > 10000);
            assert_eq!(shadowed, 0, "acne ({depth_format:?}): {shadowed} of {ground} ground pixels not fully lit at elevation {elevation}°");
        }
    }
    assert_validation_clean(&ctx);
}

#[test]
fn shadow_touches_the_casters_base_within_two_texels() {
    // A thin wall (4 cm) is where peter-panning shows: too much bias pushes the receivers behind
    // its base past the wall and they light up.
    let ctx = context();
    let half = Vec3::new(1.5, 1.0, 0.02);
    for elevation in [15.0f32, 45.0, 80.0] {
        // Sun on the +Z side: the shadow falls on −Z, behind the wall's broad face.
        let light = Light::sun(Light::sun_direction(elevation.to_radians(), 0.0), 2.0);
        let scene = caster_scene(light, half);
        let mut r = Renderer::new(&ctx, &scene).unwrap();
        let camera = Camera::look_at(
            Vec3::new(1.0, 5.0, -7.0),
            Vec3::new(0.0, 0.0, -1.0),
            55f32.to_radians(),
            0.1,
        );
        let f = r.render(&shadow_view(camera), W, H).unwrap();
        let texel = f.plan.texel_world();
        let m = f.plan.clip_from_scene();
        let mut checked = 0;
        for k in -12..=12 {
            let p = Vec3::new(k as f32 * 0.1, 0.0, -(half.z + 2.0 * texel));
            assert!(
                !exact_visible(&light, p),
                "test point must be in the exact shadow"
            );
            let Some((px, py)) = project(&m, p, W, H) else {
                continue;
            };
            let (px, py) = (px as u32, py as u32);
            if px >= W
                || py >= H
                || ground_point(&m, px, py).is_none_or(|g| g.distance(p) > 2.0 * texel)
            {
                continue;
            }
            checked += 1;
            let v = f.image.get_pixel(px, py)[0];
            if v >= 128 {
                save(&f.image, &format!("peter_panning_{elevation}.png"));
            }
            assert!(
                v < 128,
                "peter-panning at {elevation}°: {p} ({:.1} texels behind the base) is lit ({v})",
                2.0
            );
        }
        assert!(
            checked >= 10,
            "too few base points in view at {elevation}°: {checked}"
        );
    }
    assert_validation_clean(&ctx);
}

#[test]
fn sub_texel_camera_motion_leaves_shadows_unchanged_when_snapped() {
    let ctx = context();
    let light = Light::sun(Light::sun_direction(30f32.to_radians(), 0.6), 2.0);
    let scene = box_scene(light);
    let mut r = Renderer::new(&ctx, &scene).unwrap();
    let camera = camera_on_shadow_side(light.direction);
    let mut changed = [0usize; 2];
    for (i, snap) in [true, false].into_iter().enumerate() {
        let mut view = shadow_view(camera);
        view.shadow = ShadowSettings {
            snap,
            map_size: 512,
            ..Default::default()
        };
        let base = r.render(&view, W, H).unwrap();
        let texel = base.plan.texel_world();
        for step in 1..=6 {
            // Move the camera that the light frustum is fitted to by a fraction of a texel.
            let offset = Vec3::new(0.13, 0.05, 0.11) * step as f32 * texel;
            let mut moved = camera;
            moved.world_from_view = Mat4::from_translation(offset) * camera.world_from_view;
            view.shadow_fit_camera = Some(moved);
            let f = r.render(&view, W, H).unwrap();
            changed[i] += image_diff(&base.image, &f.image).over(8);
        }
    }
    let total = (W * H * 6) as usize;
    // Snapped: identical up to a stated tiny count; unsnapped: visibly shimmering.
    assert!(
        changed[0] <= total / 10000,
        "snapped fit changed {} of {total} pixels",
        changed[0]
    );
    assert!(
        changed[1] > changed[0] + 50,
        "unsnapped fit should shimmer: {} vs snapped {}",
        changed[1],
        changed[0]
    );
    assert_validation_clean(&ctx);
}

#[test]
fn spot_light_shadow_matches_geometry() {
    let ctx = context();
    let pos = Vec3::new(-4.0, 6.0, -3.0);
    let light = Light {
        kind: LightKind::Spot {
            inner: 0.5,
            outer: 0.8,
        },
        position: pos,
        direction: (Vec3::new(1.0, 0.0, 1.0) - pos).normalize(),
        color: Vec3::ONE,
        intensity: 60.0,
        casts_shadows: true,
        range: None,
        size: 0.0,
    };
    let scene = box_scene(light);
    let mut r = Renderer::new(&ctx, &scene).unwrap();
    let view = shadow_view(Camera::look_at(
        Vec3::new(9.0, 8.0, 9.0),
        Vec3::new(1.5, 0.0, 1.5),
        55f32.to_radians(),
        0.1,
    ));
    let f = r.render(&view, W, H).unwrap();
    // Texel size grows with distance; judge with the texel at the farthest shadow point (~12 units).
    let band = EDGE_TEXELS * f.plan.texel_world() * 12.0;
    let (j, diff) = judge(&f, &light, band);
    save(&f.image, "spot_shadow.png");
    save(&diff, "spot_shadow_diff.png");
    assert!(
        j.exact_shadowed > 200,
        "spot shadow in view: {}",
        j.exact_shadowed
    );
    assert_eq!(
        (j.false_shadow, j.false_light),
        (0, 0),
        "spot misclassified (of {} judged)",
        j.judged
    );
    assert_validation_clean(&ctx);
}
