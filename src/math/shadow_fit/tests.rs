#[test]
fn practical_splits() {
    // λ = 1: logarithmic (each cascade 10× deeper); λ = 0: uniform.
    let log = cascade_splits(0.1, 1000.0, 4, 1.0);
    for (a, b) in log.iter().zip([0.1, 1.0, 10.0, 100.0, 1000.0]) {
        assert!((a / b - 1.0).abs() < 1e-4, "{log:?}");
    }
    let uni = cascade_splits(0.1, 1000.0, 4, 0.0);
    assert!((uni[2] - 500.05).abs() < 1e-2, "{uni:?}");
    let mixed = cascade_splits(0.1, 1000.0, 4, 0.9);
    assert!(mixed.windows(2).all(|w| w[0] < w[1]), "{mixed:?}");
    assert_eq!(cascade_splits(0.5, 9.0, 1, 0.9), vec![0.5, 9.0]);
}

use super::*;

fn camera(eye: Vec3, target: Vec3) -> CameraFrustum {
    CameraFrustum::perspective(
        Mat4::look_at_rh(eye, target, Vec3::Y),
        0.8,
        16.0 / 9.0,
        0.1,
        60.0,
    )
}

fn scene() -> Aabb {
    Aabb::new(Vec3::new(-10.0, 0.0, -10.0), Vec3::new(10.0, 3.0, 10.0))
}

#[test]
fn intersection_points_are_inside_both() {
    let cam = camera(Vec3::new(0.0, 5.0, 15.0), Vec3::ZERO);
    let pts = frustum_box_intersection(&cam, &scene());
    assert!(!pts.is_empty());
    let grown = Aabb::new(scene().min - 1e-3, scene().max + 1e-3);
    for p in &pts {
        assert!(grown.overlaps(&Aabb::new(*p, *p)), "{p}");
    }
    // A camera looking away sees nothing of the box.
    let away = camera(Vec3::new(0.0, 5.0, 15.0), Vec3::new(0.0, 5.0, 30.0));
    assert!(frustum_box_intersection(&away, &scene()).is_empty());
}

#[test]
fn fitted_extent_at_most_scene_and_covers_receivers() {
    let dir = Vec3::new(-0.3, -1.0, -0.2).normalize();
    let cam = camera(Vec3::new(2.0, 2.0, 4.0), Vec3::new(0.0, 0.0, 0.0));
    for snap in [false, true] {
        let whole = fit_directional(&DirectionalFitInput {
            also: None,
            direction: dir,
            scene_bounds: scene(),
            camera: None,
            map_size: 2048,
            snap,
            sphere: false,
            extent_steps: 8,
            hold: None,
        });
        let fit = fit_directional(&DirectionalFitInput {
            also: None,
            direction: dir,
            scene_bounds: scene(),
            camera: Some(cam),
            map_size: 2048,
            snap,
            sphere: false,
            extent_steps: 8,
            hold: None,
        });
        let e = fit.light_box.extent();
        let w = whole.light_box.extent();
        assert!(e.x <= w.x + 1e-3 && e.y <= w.y + 1e-3, "{e} vs {w}");
        assert!(fit.texel_world < whole.texel_world);
        // Every receiver point lands inside the light's clip box.
        for p in frustum_box_intersection(&cam, &scene()) {
            let q = project(&fit.light_clip_from_world, p);
            assert!(
                q.x.abs() <= 1.0 + 1e-4 && q.y.abs() <= 1.0 + 1e-4 && (0.0..=1.0).contains(&q.z),
                "{q}"
            );
        }
        // Every scene corner (potential caster) is at depth <= 1 or clamps there; the ones
        // that can shade receivers are inside the depth range.
        for c in scene().corners() {
            let q = project(&fit.light_clip_from_world, c);
            assert!(q.z <= 1.0 + 1e-5, "caster beyond near: {q}");
        }
    }
}

#[test]
fn snapped_fit_moves_by_whole_texels() {
    let dir = Vec3::new(-0.4, -1.0, 0.3).normalize();
    let base = fit_directional(&DirectionalFitInput {
        also: None,
        direction: dir,
        scene_bounds: scene(),
        camera: Some(camera(Vec3::new(3.0, 4.0, 9.0), Vec3::ZERO)),
        map_size: 1024,
        snap: true,
        sphere: false,
        extent_steps: 8,
        hold: None,
    });
    for i in 1..20 {
        let dx = i as f32 * base.texel_world * 0.09;
        let moved = fit_directional(&DirectionalFitInput {
            also: None,
            direction: dir,
            scene_bounds: scene(),
            camera: Some(camera(
                Vec3::new(3.0 + dx, 4.0, 9.0),
                Vec3::new(dx, 0.0, 0.0),
            )),
            map_size: 1024,
            snap: true,
            sphere: false,
            extent_steps: 8,
            hold: None,
        });
        assert_eq!(moved.texel_world, base.texel_world);
        let shift = (moved.light_box.min - base.light_box.min) / base.texel_world;
        assert!(
            (shift.x - shift.x.round()).abs() < 1e-2 && (shift.y - shift.y.round()).abs() < 1e-2,
            "{shift}"
        );
    }
}

#[test]
fn quantize_is_monotone_and_bounded() {
    let mut last = 0.0;
    for i in 1..1000 {
        let x = i as f32 * 0.037;
        let q = quantize_extent(x, 8);
        assert!(q >= x * 0.9999 && q <= x * 1.0906 + 1e-6, "{x} {q}");
        assert!(q >= last);
        last = q;
    }
}

#[test]
fn spot_projection_centre_and_cone() {
    let (m, tan_half) = fit_spot(Vec3::new(0.0, 5.0, 0.0), -Vec3::Y, 0.5, &scene());
    let q = project(&m, Vec3::ZERO);
    assert!(q.x.abs() < 1e-5 && q.y.abs() < 1e-5 && q.z > 0.0 && q.z < 1.0);
    assert!(tan_half > 0.5f32.tan());
    let edge = project(&m, Vec3::new(5.0 * 0.5f32.tan(), 0.0, 0.0));
    assert!(edge.x.abs() < 1.0 && edge.x.abs() > 0.8);
}

#[test]
fn slice_sphere_holds_the_slice_tightly() {
    let perspective =
        [(0.1f32, 4.0f32, 0.8f32), (1.0, 1.5, 1.2), (0.5, 100.0, 0.3)].map(|(near, far, fov)| {
            CameraFrustum::perspective(Mat4::IDENTITY, fov, 16.0 / 9.0, near, far)
        });
    // Parallel projections: a deep box and a shallow one.
    let orthographic =
        [(0.1f32, 40.0f32, 2.0f32), (3.0, 3.5, 10.0)].map(|(near, far, h)| CameraFrustum {
            tan_half: 0.0,
            half_height: h,
            ..CameraFrustum::perspective(Mat4::IDENTITY, 1.0, 4.0 / 3.0, near, far)
        });
    for c in perspective.into_iter().chain(orthographic) {
        let (z, r) = slice_sphere(&c);
        let centre = Vec3::new(0.0, 0.0, -z);
        let d: Vec<f32> = c.corners().iter().map(|p| p.distance(centre)).collect();
        let widest = d.iter().copied().fold(0.0, f32::max);
        // Every corner inside, the farthest on the sphere.
        assert!((widest / r - 1.0).abs() < 1e-4, "{d:?} vs {r}");
    }
}

#[test]
fn sphere_fit_keeps_its_size_as_the_camera_moves_and_turns() {
    let dir = Vec3::new(-0.3, -1.0, -0.2).normalize();
    let fit = |eye: Vec3, target: Vec3, sphere: bool| {
        let cam = CameraFrustum {
            far: 4.0,
            ..camera(eye, target)
        };
        let f = fit_directional(&DirectionalFitInput {
            also: None,
            direction: dir,
            scene_bounds: scene(),
            camera: Some(cam),
            map_size: 1024,
            snap: true,
            sphere,
            extent_steps: 8,
            hold: None,
        });
        // Every receiver it sees lands inside the map.
        for p in frustum_box_intersection(&cam, &scene()) {
            let q = project(&f.light_clip_from_world, p);
            assert!(q.x.abs() <= 1.0 + 1e-4 && q.y.abs() <= 1.0 + 1e-4, "{q}");
        }
        f.texel_world
    };
    let poses = [
        (Vec3::new(0.0, 1.5, 0.0), Vec3::new(3.0, 0.0, 1.0)),
        (Vec3::new(-4.0, 2.0, 5.0), Vec3::new(-4.0, 0.0, 1.0)),
        (Vec3::new(6.0, 1.0, -6.0), Vec3::new(9.0, 1.5, -6.5)),
        (Vec3::new(2.0, 2.5, 2.0), Vec3::new(2.5, 0.0, 2.2)),
    ];
    let sphere: Vec<f32> = poses.iter().map(|&(e, t)| fit(e, t, true)).collect();
    assert!(sphere.iter().all(|&t| t == sphere[0]), "{sphere:?}");
    // The receivers' fit changes size with the same moves, and is finer.
    let tight: Vec<f32> = poses.iter().map(|&(e, t)| fit(e, t, false)).collect();
    assert!(tight.iter().any(|&t| t != tight[0]), "{tight:?}");
    assert!(
        tight.iter().all(|&t| t <= sphere[0]),
        "{tight:?} vs {sphere:?}"
    );
}

#[test]
fn widened_only_grows_by_doublings() {
    assert_eq!(widened(4.0, 3.0), 4.0);
    assert_eq!(widened(4.0, 0.5), 4.0);
    assert_eq!(widened(4.0, 4.0), 4.0);
    assert_eq!(widened(4.0, 5.0), 8.0);
    assert_eq!(widened(4.0, 17.0), 32.0);
    assert_eq!(widened(f32::NAN, 3.0), 3.0);
}

#[test]
fn held_extent_steps_by_doublings() {
    // Kept while it covers at most one doubling too coarse.
    assert_eq!(held_extent(4.0, 3.0), 4.0);
    assert_eq!(held_extent(4.0, 2.0), 4.0);
    assert_eq!(held_extent(4.0, 4.0), 4.0);
    // Stepped by whole doublings, to the nearest at least the need.
    assert_eq!(held_extent(4.0, 1.9), 2.0);
    assert_eq!(held_extent(4.0, 0.9), 1.0);
    assert_eq!(held_extent(4.0, 4.1), 8.0);
    assert_eq!(held_extent(4.0, 17.0), 32.0);
    // A zoom in by 4.75x steps twice (on the 2^(1/8) ladder: 18 times).
    let mut h = quantize_extent(4.75, 8);
    let mut steps = 0;
    for i in 1..=100 {
        let need = 4.75f32.powf(1.0 - i as f32 / 100.0);
        let next = held_extent(h, need);
        assert!(next >= need && next <= 2.0 * need + 1e-6);
        steps += (next != h) as u32;
        h = next;
    }
    assert_eq!(steps, 2);
}
