use super::*;

/// `plan_frame` at the world origin with software depth comparison.
fn plan_at(
    lights: &[Light],
    bounds: &Aabb,
    receivers: &[Aabb],
    view: &View,
    aspect: f32,
    height_px: u32,
) -> FramePlan {
    let scene = PlanScene {
        lights,
        bounds,
        receivers,
        planes: &[],
        origin: Vec3::ZERO,
    };
    let target = PlanTarget {
        aspect,
        height_px,
        hw_compare: false,
        exact_capable: true,
        receiver_split: false,
    };
    plan_frame(&scene, view, &target)
}
use crate::plan::lights::*;
use crate::plan::view::{AUTO_GROUND, AUTO_SKY, GROUND_TINT, SKY_TINT};
use crate::scene::Camera;

#[test]
fn metering_takes_the_median_receiver_and_walls_for_an_inside_lamp() {
    let lamp = Light {
        kind: LightKind::Point,
        position: Vec3::ZERO,
        direction: Vec3::NEG_Y,
        color: Vec3::ONE,
        intensity: 100.0,
        casts_shadows: false,
        range: None,
        size: 0.0,
    };
    let room = Aabb::new(Vec3::splat(-5.0), Vec3::splat(5.0));
    // A lamp inside a room is metered at the room's half-diagonal: 100 / 75.
    let e = metered_illuminance(&[lamp], Vec3::ZERO, &[room], &room);
    assert!((e - 100.0 / 75.0).abs() < 1e-5, "{e}");
    // Three small boxes 1, 2 and 10 m away: the median is the one 2 m away (100 / 4).
    let boxes: Vec<Aabb> = [1.0f32, 2.0, 10.0]
        .iter()
        .map(|&d| Aabb::new(Vec3::new(d, -0.01, -0.01), Vec3::new(d, 0.01, 0.01)))
        .collect();
    let e = metered_illuminance(&[lamp], Vec3::splat(0.5), &boxes, &room);
    assert!((e - (25.0 + 0.5)).abs() < 1e-3, "{e}");
    // A sun meters its intensity wherever the receivers are; the default sky is a fifth of
    // it, the ground 6 %, and exposure meters the sun plus their mean.
    let sun = Light::sun(Vec3::NEG_Y, 3.0);
    let v = View::new(crate::scene::Camera::look_at(
        Vec3::new(0.0, 2.0, 8.0),
        Vec3::ZERO,
        0.8,
        0.1,
    ));
    let p = plan_at(&[sun], &room, &boxes, &v, 1.5, 100);
    assert!((p.ambient.sky - SKY_TINT * (AUTO_SKY * 3.0)).length() < 1e-5);
    assert!((p.ambient.ground - GROUND_TINT * (AUTO_GROUND * 3.0)).length() < 1e-5);
    let k = crate::math::tonemap::KEY_VALUE;
    let mean = 0.5 * (AUTO_SKY * luminance(SKY_TINT) + AUTO_GROUND * luminance(GROUND_TINT));
    assert!((p.exposure - k / (3.0 * (1.0 + mean))).abs() < 1e-5);
    // A flat ambient is what it says from every direction.
    let mut flat = v.clone();
    flat.ambient = Some(Vec3::splat(0.25));
    let p = plan_at(&[sun], &room, &boxes, &flat, 1.5, 100);
    assert_eq!(p.ambient.at(Vec3::X), Vec3::splat(0.25));
}

#[test]
fn the_hemisphere_mixes_ground_to_sky_by_the_up_component() {
    // The tints keep the luminance the shares give.
    assert!((luminance(SKY_TINT) - 1.0).abs() < 1e-3);
    assert!((luminance(GROUND_TINT) - 1.0).abs() < 1e-3);
    let a = Ambient {
        sky: Vec3::new(1.0, 2.0, 3.0),
        ground: Vec3::new(0.5, 0.0, 1.0),
    };
    assert_eq!(a.at(Vec3::Y), a.sky);
    assert_eq!(a.at(Vec3::NEG_Y), a.ground);
    assert_eq!(a.at(Vec3::Z), a.mean());
    let tilted = Vec3::new(0.0, 0.5, 0.75f32.sqrt());
    assert!((a.at(tilted) - (a.ground * 0.25 + a.sky * 0.75)).length() < 1e-6);
}
use crate::scene::built::demo::demo_scene;

#[test]
fn default_sun_and_override() {
    let mut s = demo_scene();
    s.lights.clear();
    let mut v = View::new(s.default_camera(1.5));
    let p = plan_at(&s.lights, &s.bounds(), &[], &v, 1.5, 720);
    // The compact demo keeps one map by default (automatic cascade count).
    assert_eq!(p.shadow_views.len(), 1);
    assert_eq!(p.lights.len(), 1);
    assert_eq!(p.shadow_light, Some(0));
    assert!(p.texel_world() > 0.0);
    v.sun_direction = Some(Vec3::new(0.0, -1.0, 0.0));
    let p = plan_at(&s.lights, &s.bounds(), &[], &v, 1.5, 720);
    assert_eq!(p.lights[0].direction, Vec3::NEG_Y);
    assert_eq!(p.uniform.modes[3], 1);
    // One light, shadows on, PCF 2×2 by hand (hw_compare false).
    use crate::shader_consts::VariantKey as K;
    let want = K::ONE_SUN | K::SHADOWS | K::PCF_BIT0;
    assert_eq!(p.shader_variant, want);
    // Cascades: four views, nearest first, each ending where the next blends in.
    v.shadow.cascades = 4;
    let p = plan_at(&s.lights, &s.bounds(), &[], &v, 1.5, 720);
    assert_eq!(p.shader_variant, want | K::MANY_VIEWS);
    assert_eq!(p.shadow_views.len(), 4);
    for w in p.shadow_views.windows(2) {
        assert!(w[0].blend < w[0].far && w[0].far < w[1].far, "{w:?}");
        assert!(w[0].texel_world > 0.0 && w[1].texel_world > 0.0, "{w:?}");
    }
    assert!(p.shadow_views[3].far.is_infinite());
    // Without shadows the filter, comparison and cascade bits mean nothing: one shader.
    v.shadow.enabled = false;
    let p = plan_at(&s.lights, &s.bounds(), &[], &v, 1.5, 720);
    assert_eq!(p.shader_variant, K::ONE_SUN);
    // One point light is not a sun: the general light loop.
    let point = [Light {
        kind: LightKind::Point,
        position: Vec3::new(0.0, 3.0, 0.0),
        ..Light::sun(Vec3::NEG_Y, 10.0)
    }];
    v.sun_direction = None;
    let p = plan_at(&point, &s.bounds(), &[], &v, 1.5, 720);
    assert_eq!(p.lights.len(), 1);
    assert!(!p.shader_variant.contains(K::ONE_SUN));
}
#[test]
fn the_automatic_setting_doubles_one_map_before_it_splits_into_cascades() {
    // The demo at its own camera, planned without depths seen: one 2048² map's texel is
    // 0.463 pixels at the nearest receiver at 720 rows (measured), growing with the rows.
    let s = demo_scene();
    let planner = ScenePlanner::new(&s);
    let v = View::new(s.default_camera(16.0 / 9.0));
    let plan = |v: &View, rows: u32| planner.plan(v, rows * 16 / 9, rows);
    let one = plan(&v, 720);
    assert_eq!(one.shadow_views.len(), 1);
    let texel = one.shadow_views[0].texel_world;
    let ratio_at = |rows: u32| 0.463 * rows as f32 / 720.0;
    // Ratio 3.86: one map as set.
    let p = plan(&v, 6000);
    assert!(ratio_at(6000) < 4.0);
    assert_eq!((p.shadow_views.len(), p.shadow_views[0].res), (1, 2048));
    assert_eq!(p.shadow_map_size(), 2048);
    // Ratio 4.5: one map of twice the side, half the texel (within the fit's rounding).
    let p = plan(&v, 7000);
    assert!(ratio_at(7000) > 4.0 && ratio_at(7000) < 5.0);
    assert_eq!((p.shadow_views.len(), p.shadow_views[0].res), (1, 4096));
    assert_eq!(p.shadow_map_size(), 4096);
    assert_eq!(p.uniform.shadow.x, 4096.0);
    let half = p.shadow_views[0].texel_world / (texel * 0.5);
    assert!(
        (0.9..1.1).contains(&half),
        "texel {half} × half the 2048² map's"
    );
    // Ratio 5.5: two cascades of the set size.
    let p = plan(&v, 8500);
    assert!(ratio_at(8500) > 5.0);
    assert_eq!(p.shadow_views.len(), 2);
    assert!(p.shadow_views.iter().all(|sv| sv.res == 2048));
    assert_eq!(p.shadow_map_size(), 2048);
    // A fixed count, or a map already at the largest doubled side, is never doubled.
    let mut fixed = v.clone();
    fixed.shadow.cascades = 1;
    assert_eq!(plan(&fixed, 7000).shadow_map_size(), 2048);
    let mut big = v.clone();
    big.shadow.map_size = 4096;
    let p = plan(&big, 15000);
    assert_eq!((p.shadow_views.len(), p.shadow_map_size()), (2, 4096));
}

#[test]
fn held_cascades_keep_their_splits_until_the_receivers_leave_them() {
    let s = demo_scene();
    let sun = [Light::sun(Vec3::new(0.3, -1.0, 0.2), 1.0)];
    let cam = s.default_camera(1.5);
    let (c, eye) = (s.bounds().center(), cam.position());
    let fov = cam.fov_y().unwrap();
    let at = |k: f32| Camera::look_at(c + (eye - c) * k, c, fov, cam.near);
    let mut v = View::new(cam);
    v.shadow.cascades = 4;
    let plan = |v: &View| plan_at(&sun, &s.bounds(), &[], v, 1.5, 720);
    let range = |p: &FramePlan| p.primary_views()[0].depth_range.unwrap();
    let splits = |p: &FramePlan| p.primary_views().iter().map(|v| v.far).collect::<Vec<_>>();
    let first = plan(&v);
    let r0 = range(&first);
    // Closer in, fitted afresh, the range narrows: its far end comes more than a doubling
    // nearer (measured 63.4 -> 30.8).
    v.camera = at(0.3);
    let fresh = range(&plan(&v));
    assert!(fresh.1 < 0.5 * r0.1, "{fresh:?} vs {r0:?}");
    // Held, its far end stays where it was (its near end follows the receivers closer, by
    // doublings, down to the fitting frustum's near plane: measured 26.9 -> 15.0).
    v.shadow_hold = Some(crate::plan::ShadowHold::from_plan(&first));
    let held = range(&plan(&v));
    assert_eq!(held.1, r0.1, "{held:?} vs {r0:?}");
    assert!(held.0 <= fresh.0 && held.0 < r0.0, "{held:?} vs {fresh:?}");
    // A camera that has not moved keeps the very same splits.
    v.camera = cam;
    assert_eq!(splits(&plan(&v)), splits(&first));
    // Drawn back until the receivers pass its far end, it widens by a whole doubling.
    v.camera = at(2.0);
    let need = range(&{
        let mut u = v.clone();
        u.shadow_hold = None;
        plan(&u)
    });
    let wide = range(&plan(&v));
    assert!(need.1 > r0.1, "{need:?} vs {r0:?}");
    assert_eq!(
        wide.1,
        r0.1 * (need.1 / r0.1).log2().ceil().exp2(),
        "{need:?}"
    );
}

#[test]
fn every_casting_light_gets_views_while_they_last() {
    let s = demo_scene();
    let point = |x: f32| Light {
        kind: LightKind::Point,
        position: Vec3::new(x, 3.0, 0.0),
        direction: Vec3::NEG_Y,
        color: Vec3::ONE,
        intensity: 5.0,
        casts_shadows: true,
        range: None,
        size: 0.0,
    };
    let spot = Light {
        kind: LightKind::Spot {
            inner: 0.3,
            outer: 0.5,
        },
        ..point(1.0)
    };
    let mut dark = point(0.0);
    dark.casts_shadows = false;
    let sun = Light::sun(Vec3::new(0.3, -1.0, 0.2), 1.0);
    let lights = vec![sun, point(-2.0), dark, spot, point(2.0), point(4.0)];
    let mut v = View::new(s.default_camera(1.5));
    v.shadow.cascades = 4;
    let p = plan_at(&lights, &s.bounds(), &[], &v, 1.5, 720);
    // Sun 4 cascades, point 6 faces, spot 1: 11 of 16; the next two point lights need 6
    // each, more than the 5 left, and the light that casts none gets none.
    let per_light: Vec<usize> = (0..lights.len()).map(|i| p.light_views(i).len()).collect();
    assert_eq!(per_light, [4, 6, 0, 1, 0, 0]);
    assert_eq!(p.unshadowed, [4, 5]);
    assert_eq!(p.shadow_views.len(), 11);
    assert!(p.is_shadowed(3) && !p.is_shadowed(2) && !p.is_shadowed(4));
    // Layer order: grouped by light; the uniform says where each light's views start.
    let firsts: Vec<f32> = p.uniform.lights[..6].iter().map(|l| l.shadow.x).collect();
    assert_eq!(firsts, [0.0, 4.0, -1.0, 10.0, -1.0, -1.0]);
    assert_eq!(
        p.shader_variant & crate::shader_consts::VariantKey::MANY_VIEWS,
        crate::shader_consts::VariantKey::MANY_VIEWS
    );
    // The shown light: the first shadowed one, or the one asked for if it has views.
    assert_eq!(p.shadow_light, Some(0));
    v.shown_light = Some(3);
    let p = plan_at(&lights, &s.bounds(), &[], &v, 1.5, 720);
    assert_eq!(
        (
            p.shadow_light,
            p.uniform.lights[3].shadow.x,
            p.uniform.lights[3].shadow.y
        ),
        (Some(3), 10.0, 1.0)
    );
    v.shown_light = Some(4);
    let p = plan_at(&lights, &s.bounds(), &[], &v, 1.5, 720);
    assert_eq!(p.shadow_light, Some(0));
    // A point light's faces look along ±x, ±y, ±z: each face's centre direction lands in the
    // middle of its own layer.
    let faces = p.light_views(1);
    let at = lights[1].position;
    for (k, d) in [
        Vec3::X,
        Vec3::NEG_X,
        Vec3::Y,
        Vec3::NEG_Y,
        Vec3::Z,
        Vec3::NEG_Z,
    ]
    .iter()
    .enumerate()
    {
        let c = faces[k].light_clip_from_world * (at + *d).extend(1.0);
        let ndc = c.truncate() / c.w;
        assert!(
            ndc.x.abs() < 1e-4 && ndc.y.abs() < 1e-4 && c.w > 0.0,
            "face {k}: {ndc}"
        );
    }
}

#[test]
fn auto_format_takes_d16_only_where_its_step_is_under_a_quarter_of_the_bias() {
    // A directional view 10 units deep: one D16 step is 10 / 65535 = 1.5e-4 units.
    let ortho = |depth: f32| Mat4::orthographic_rh(-5.0, 5.0, -5.0, 5.0, 0.0, depth);
    let view = |m: Mat4, texel: f32| ShadowView::whole(m, texel);
    let auto = ShadowSettings::default();
    assert_eq!(auto.format, ShadowFormat::Auto);
    // 10 units on 2048 texels: texel 4.9e-3, a quarter of a 1-texel bias 1.2e-3 ≥ 1.5e-4.
    let near = view(ortho(10.0), 10.0 / 2048.0);
    assert_eq!(
        resolve_format(&auto, std::slice::from_ref(&near)),
        ShadowFormat::D16
    );
    // 1,000 units deep for the same texels: a step of 0.015 is past the quarter bias.
    let deep = view(ortho(1000.0), 10.0 / 2048.0);
    assert_eq!(
        resolve_format(&auto, &[near.clone(), deep]),
        ShadowFormat::D32
    );
    // The limit: depth ≤ 65535 × 0.25 × bias × texel = 80 units here.
    assert_eq!(
        resolve_format(&auto, &[view(ortho(79.0), 10.0 / 2048.0)]),
        ShadowFormat::D16
    );
    assert_eq!(
        resolve_format(&auto, &[view(ortho(81.0), 10.0 / 2048.0)]),
        ShadowFormat::D32
    );
    // Perspective depth (a spot light) and no constant bias keep D32; explicit formats pass.
    let spot = view(Mat4::perspective_rh(1.0, 1.0, 0.1, 10.0), 1e-3);
    assert_eq!(resolve_format(&auto, &[spot]), ShadowFormat::D32);
    let unbiased = ShadowSettings {
        constant_bias: 0.0,
        ..auto
    };
    assert_eq!(
        resolve_format(&unbiased, std::slice::from_ref(&near)),
        ShadowFormat::D32
    );
    let d32 = ShadowSettings {
        format: ShadowFormat::D32,
        ..auto
    };
    assert_eq!(resolve_format(&d32, &[near]), ShadowFormat::D32);
    assert_eq!(resolve_format(&auto, &[]), ShadowFormat::D32);
}
