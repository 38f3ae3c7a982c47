//! Scenes that move: the project's own animated models (a two-joint skinned bar, a hierarchy
//! animated with STEP, LINEAR and CUBICSPLINE, a cube with two morph targets), written by
//! `crate::common::gltf_builder`, loaded, posed at several times and rendered on lavapipe with
//! validation. Where things must be is computed here from the models' definitions (not by the
//! code under test), and the shadows are judged against the exact ray-cast reference.

use crate::common::animated;
use crate::common::{assert_validation_clean, context, project, save};
use glam::{Mat4, Quat, Vec3};
use std::path::PathBuf;
use umbra::scene::anim::Playing;
use umbra::scene::built::shapes::{add_object, colored, plane};
use umbra::scene::{gltf::load_gltf, Camera, Scene};
use umbra::{RenderedFrame, Renderer, View};
use umbra_lab::reference::{classify, PixelClass, ReferenceScene};

const W: u32 = 480;
const H: u32 = 360;

fn model_dir() -> PathBuf {
    let d = crate::common::out_dir().join("animated-models");
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A grey ground 20 across at y = `y` (a receiver for the shadows).
fn add_floor(scene: &mut Scene, y: f32) {
    add_object(
        scene,
        "floor",
        plane(20.0, 1.0),
        colored(Vec3::splat(0.7), 0.9),
        Mat4::from_translation(Vec3::new(0.0, y, 0.0)),
    );
}

fn view(eye: Vec3, target: Vec3, fov_degrees: f32) -> View {
    let mut v = View::new(Camera::look_at(eye, target, fov_degrees.to_radians(), 0.05));
    v.sun_direction = Some(Vec3::new(-0.35, -1.0, -0.45));
    v
}

/// Renders `scene` (with depth) by a fresh renderer.
fn render(ctx: &std::sync::Arc<umbra::Context>, scene: &Scene, v: &View) -> RenderedFrame {
    let mut r = Renderer::new(ctx, scene).unwrap();
    r.set_read_depth(true);
    r.render(v, W, H).unwrap()
}

/// Whether the model (anything at all, the scene having no floor) covers the pixel nearest the
/// projection of `p`.
fn covered(f: &RenderedFrame, p: Vec3) -> bool {
    let (x, y) = project(&f.plan.clip_from_scene(), p, W, H).expect("in front");
    let (x, y) = (x.floor() as u32, y.floor() as u32);
    assert!(x < W && y < H, "{p} projects off screen");
    f.depth.as_ref().unwrap()[(y * W + x) as usize] > 0.0
}

/// Misclassified pixels away from the exact shadow's edges, and pixels judged, against the
/// exact ray-cast reference.
fn interior_misclassified(f: &RenderedFrame, scene: &Scene) -> (usize, usize) {
    let exact = ReferenceScene::new(scene).render(&f.plan, W, H, f.plan.ambient);
    let c = classify(&f.image, f.depth.as_deref().unwrap(), &f.plan, &exact);
    let (mut judged, mut wrong) = (0, 0);
    for (i, class) in c.class.iter().enumerate() {
        if *class != PixelClass::Unjudged && !c.edge[i] {
            judged += 1;
            wrong += matches!(class, PixelClass::FalseShadow | PixelClass::FalseLight) as usize;
        }
    }
    (wrong, judged)
}

/// The shadow-visibility view of the same frame, with depth.
fn shadow_frame(ctx: &std::sync::Arc<umbra::Context>, scene: &Scene, v: &View) -> RenderedFrame {
    let mut v = v.clone();
    v.mode = umbra::plan::ViewMode::Shadow;
    render(ctx, scene, &v)
}

/// Where the top of the bar's cap is when joint 1 stands at `degrees` about Z around (0, 1, 0),
/// and points along its axis: computed from the model's definition.
fn bar_axis(degrees: f32, s: f32) -> Vec3 {
    let a = degrees.to_radians();
    Vec3::new(0.0, 1.0, 0.0) + Vec3::new(-a.sin(), a.cos(), 0.0) * s
}

#[test]
fn the_skinned_bar_bends_where_its_joint_turns() {
    let ctx = context();
    let path = animated::skinned_bar(&model_dir(), "skinned_bar", 0.0, true);
    let v = view(Vec3::new(0.0, 1.2, 7.0), Vec3::new(0.0, 1.2, 0.0), 45.0);
    for (t, degrees) in [(0.0, 0.0), (0.5, 45.0), (1.0, 90.0), (3.0, 90.0)] {
        let mut scene = load_gltf(&path).unwrap();
        scene.pose_at(&Playing::One(0), t);
        let f = render(&ctx, &scene, &v);
        save(&f.image, &format!("skinned_bar_t{t}.png"));
        // Along the bent upper half: covered. Where the straight bar's top would be: empty,
        // once the joint has turned 45° or more.
        for s in [0.3, 0.6, 0.9] {
            assert!(
                covered(&f, bar_axis(degrees, s)),
                "t {t}: axis at {s} not drawn"
            );
        }
        if degrees >= 45.0 {
            assert!(
                !covered(&f, bar_axis(0.0, 0.9)),
                "t {t}: the straight top is still drawn"
            );
        }
        // The lower half never moves.
        assert!(covered(&f, Vec3::new(0.0, 0.5, 0.0)));
    }
    assert_validation_clean(&ctx);
}

#[test]
fn a_skinned_mesh_at_rest_is_drawn_where_its_joints_put_it() {
    // No animation: joint 1 rests turned 60°, while the stored vertices are straight.
    let ctx = context();
    let scene = load_gltf(&animated::skinned_bar(
        &model_dir(),
        "bent_at_rest",
        60.0,
        false,
    ))
    .unwrap();
    let v = view(Vec3::new(0.0, 1.2, 7.0), Vec3::new(0.0, 1.2, 0.0), 45.0);
    let f = render(&ctx, &scene, &v);
    save(&f.image, "skinned_bar_rest.png");
    for s in [0.3, 0.6, 0.9] {
        assert!(covered(&f, bar_axis(60.0, s)), "axis at {s} not drawn");
    }
    assert!(
        !covered(&f, bar_axis(0.0, 0.9)),
        "drawn as stored, not as skinned"
    );
    // The pose the scene holds is the skinned one: the top cap's centre (its last 4 vertices)
    // is where joint 1 puts it.
    let positions = &scene.meshes[0].primitives[0].positions;
    let top = positions[positions.len() - 4..]
        .iter()
        .fold(Vec3::ZERO, |a, p| a + *p)
        / 4.0;
    assert!(top.abs_diff_eq(bar_axis(60.0, 1.0), 1e-5), "{top}");
    assert_validation_clean(&ctx);
}

#[test]
fn the_bent_bars_shadow_agrees_with_the_exact_reference() {
    let ctx = context();
    let path = animated::skinned_bar(&model_dir(), "skinned_bar_shadow", 0.0, true);
    let v = view(Vec3::new(2.0, 3.0, 6.0), Vec3::new(0.0, 0.8, 0.0), 50.0);
    for t in [0.25, 1.0] {
        let mut scene = load_gltf(&path).unwrap();
        scene.pose_at(&Playing::One(0), t);
        add_floor(&mut scene, 0.0);
        let f = shadow_frame(&ctx, &scene, &v);
        save(&f.image, &format!("skinned_bar_shadow_t{t}.png"));
        let (wrong, judged) = interior_misclassified(&f, &scene);
        eprintln!("bar at t {t}: {wrong} of {judged} judged pixels misclassified");
        assert!(judged > (W * H / 2) as usize, "{judged}");
        // Measured: 0 of ~160k at both times (still scenes: 0 to 0.02 %).
        assert!(wrong as f64 <= 2e-4 * judged as f64, "{wrong} of {judged}");
        // The bar's shadow is there: some floor pixels are dark.
        let dark = f.image.pixels().filter(|p| p[0] < 64).count();
        assert!(dark > 500, "only {dark} shadowed pixels");
    }
    assert_validation_clean(&ctx);
}

/// The hermite basis, written out again from the glTF spec for the test.
fn spec_hermite(s: f32) -> [f32; 4] {
    [
        2.0 * s.powi(3) - 3.0 * s * s + 1.0,
        s.powi(3) - 2.0 * s * s + s,
        -2.0 * s.powi(3) + 3.0 * s * s,
        s.powi(3) - s * s,
    ]
}

/// World centres of the three cubes of `animated::hierarchy(&model_dir())` at time `t`, from its definition.
fn hierarchy_centres(t: f32) -> [Vec3; 3] {
    let root = Vec3::new(if t < 1.0 { -1.0 } else { 1.0 }, 0.0, 0.0);
    let theta = (45.0 * t.clamp(0.0, 2.0)).to_radians();
    let child = root + Vec3::new(0.0, 1.2, 0.0);
    let [_, h10, _, h11] = spec_hermite((t / 2.0).clamp(0.0, 1.0));
    let g = Vec3::new(0.0, 1.2, 0.0) + Vec3::X * (h10 * 2.0 * 0.5) + Vec3::X * (h11 * 2.0 * -0.5);
    let grand = child + Quat::from_rotation_z(theta) * g;
    [root, child, grand]
}

#[test]
fn a_hierarchy_follows_step_linear_and_cubic_spline_keys() {
    let ctx = context();
    let path = animated::hierarchy(&model_dir());
    let v = view(Vec3::new(0.0, 1.2, 14.0), Vec3::new(0.0, 1.2, 0.0), 30.0).raw_output();
    for t in [0.0, 0.5, 1.5, 2.0] {
        let mut scene = load_gltf(&path).unwrap();
        scene.pose_at(&Playing::One(0), t);
        let f = render(&ctx, &scene, &v);
        save(&f.image, &format!("hierarchy_t{t}.png"));
        let centres = hierarchy_centres(t);
        for (k, c) in centres.iter().enumerate() {
            // The centroid of the pixels of cube k's colour against its projected centre.
            let (mut sx, mut sy, mut n) = (0.0, 0.0, 0usize);
            for (x, y, p) in f.image.enumerate_pixels() {
                let ch = [p[0], p[1], p[2]];
                if ch[k] > 200 && ch[(k + 1) % 3] < 60 && ch[(k + 2) % 3] < 60 {
                    sx += x as f32 + 0.5;
                    sy += y as f32 + 0.5;
                    n += 1;
                }
            }
            assert!(n > 200, "t {t}: cube {k} has {n} pixels");
            let (px, py) = project(&f.plan.clip_from_scene(), *c, W, H).unwrap();
            let (cx, cy) = (sx / n as f32, sy / n as f32);
            // Measured: within 0.3 px (perspective moves a turned cube's centroid a little).
            let off = ((cx - px).powi(2) + (cy - py).powi(2)).sqrt();
            assert!(
                off < 0.75,
                "t {t}: cube {k} centroid ({cx:.2}, {cy:.2}) vs ({px:.2}, {py:.2})"
            );
        }
    }
    assert_validation_clean(&ctx);
}

/// The silhouette's topmost row and rightmost column (pixels covered by the model).
fn extent(f: &RenderedFrame) -> (u32, u32) {
    let d = f.depth.as_ref().unwrap();
    let (mut top, mut right) = (H, 0);
    for y in 0..H {
        for x in 0..W {
            if d[(y * W + x) as usize] > 0.0 {
                top = top.min(y);
                right = right.max(x);
            }
        }
    }
    (top, right)
}

#[test]
fn morph_targets_take_default_and_animated_weights() {
    let ctx = context();
    let path = animated::morph_cube(&model_dir());
    let v = view(Vec3::new(0.25, 0.5, 12.0), Vec3::new(0.25, 0.5, 0.0), 20.0);
    // (time or rest, weights the model's definition gives then).
    let cases: [(Option<f32>, [f32; 2]); 4] = [
        (None, [0.5, 0.0]),
        (Some(0.0), [0.0, 0.0]),
        (Some(0.5), [0.5, 0.5]),
        (Some(1.0), [1.0, 1.0]),
    ];
    for (t, w) in cases {
        let mut scene = load_gltf(&path).unwrap();
        if let Some(t) = t {
            scene.pose_at(&Playing::One(0), t);
        }
        let f = render(&ctx, &scene, &v);
        save(&f.image, &format!("morph_cube_{t:?}.png"));
        let (top, right) = extent(&f);
        // The nearest top and right edges (z = 0.5) bound the silhouette.
        let m = f.plan.clip_from_scene();
        let (_, want_top) = project(&m, Vec3::new(0.25, 0.5 + w[0], 0.5), W, H).unwrap();
        let (want_right, _) = project(&m, Vec3::new(0.5 + w[1], 0.5, 0.5), W, H).unwrap();
        eprintln!("{t:?}: top {top} (want {want_top:.2}), right {right} (want {want_right:.2})");
        // A pixel is covered when its centre is inside: the edge falls within that pixel.
        assert!(
            (top as f32 + 0.5 - want_top).abs() <= 1.0,
            "{t:?}: top {top} vs {want_top}"
        );
        assert!(
            (right as f32 + 0.5 - want_right).abs() <= 1.0,
            "{t:?}: right {right} vs {want_right}"
        );
    }
    assert_validation_clean(&ctx);
}

#[test]
fn morphed_and_hierarchy_shadows_agree_with_the_exact_reference() {
    let ctx = context();
    let v = view(Vec3::new(3.0, 4.0, 8.0), Vec3::new(0.0, 1.0, 0.0), 50.0);
    for (path, t) in [
        (animated::morph_cube(&model_dir()), 0.75),
        (animated::hierarchy(&model_dir()), 1.5),
    ] {
        let mut scene = load_gltf(&path).unwrap();
        scene.pose_at(&Playing::One(0), t);
        add_floor(&mut scene, -0.6);
        let f = shadow_frame(&ctx, &scene, &v);
        save(&f.image, &format!("{}_shadow.png", scene.name));
        let (wrong, judged) = interior_misclassified(&f, &scene);
        eprintln!("{} at t {t}: {wrong} of {judged} misclassified", scene.name);
        assert!(judged > (W * H / 2) as usize, "{judged}");
        // Measured: 0 at both (still scenes: 0 to 0.02 %).
        assert!(wrong as f64 <= 2e-4 * judged as f64, "{wrong} of {judged}");
    }
    assert_validation_clean(&ctx);
}

#[test]
fn a_renderer_posed_in_place_draws_what_a_fresh_one_draws() {
    // Renderer::set_pose rewrites vertices and draws in place; the frame must be the one a
    // renderer made from the posed scene draws, to the bit, shadows included.
    let ctx = context();
    let path = animated::skinned_bar(&model_dir(), "skinned_bar_in_place", 0.0, true);
    let mut scene = load_gltf(&path).unwrap();
    add_floor(&mut scene, 0.0);
    let v = view(Vec3::new(2.0, 3.0, 6.0), Vec3::new(0.0, 0.8, 0.0), 50.0);
    let mut live = Renderer::new(&ctx, &scene).unwrap();
    let first = live.render(&v, W, H).unwrap().image;
    for t in [0.3, 0.8] {
        scene.pose_at(&Playing::One(0), t);
        live.set_pose(&scene).unwrap();
        let a = live.render(&v, W, H).unwrap().image;
        let b = Renderer::new(&ctx, &scene)
            .unwrap()
            .render(&v, W, H)
            .unwrap()
            .image;
        let differ = a.pixels().zip(b.pixels()).filter(|(p, q)| p != q).count();
        assert_eq!(differ, 0, "t {t}: {differ} pixels differ");
        let moved = a
            .pixels()
            .zip(first.pixels())
            .filter(|(p, q)| p != q)
            .count();
        assert!(moved > 1000, "t {t}: only {moved} pixels changed from rest");
    }
    drop(live);
    assert_validation_clean(&ctx);
}

#[test]
fn fox_walks_and_its_shadow_follows() {
    let Some(dir) = crate::common::corpus::extra_corpus() else {
        eprintln!("UMBRA_GLTF_CORPUS not set: Fox.glb not tried");
        return;
    };
    let ctx = context();
    let fox = dir.join("Fox.glb");
    let mut scene = load_gltf(&fox).unwrap();
    let rig = scene.rig.clone().expect("Fox has a rig");
    let names: Vec<&str> = rig.animations.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["Survey", "Walk", "Run"]);
    umbra::scene::built::shapes::add_ground(&mut scene);
    let mut v = view(Vec3::ZERO, Vec3::X, 45.0);
    v.camera = scene.default_camera(W as f32 / H as f32);
    let mut shadows = Vec::new();
    for t in [0.0, 0.3, 0.6] {
        scene.pose_at(&Playing::One(1), t);
        let f = shadow_frame(&ctx, &scene, &v);
        save(&f.image, &format!("fox_walk_shadow_t{t}.png"));
        let (wrong, judged) = interior_misclassified(&f, &scene);
        eprintln!("Fox walking at t {t}: {wrong} of {judged} misclassified");
        // Measured: at most 0.01 % (still scenes: 0 to 0.02 %).
        assert!(wrong as f64 <= 5e-4 * judged as f64, "{wrong} of {judged}");
        shadows.push(f.image);
    }
    for k in 1..shadows.len() {
        let moved = shadows[k]
            .pixels()
            .zip(shadows[k - 1].pixels())
            .filter(|(a, b)| (a[0] < 128) != (b[0] < 128))
            .count();
        assert!(
            moved > 200,
            "the shadow did not move between frames {} and {k}",
            k - 1
        );
    }
    assert_validation_clean(&ctx);
}

/// A one-triangle model animated by `sampler` (times, values, interpolation) on `path`, with a
/// skin on its node whose vertex 0 names `joint` with weights `w0`.
fn broken(
    name: &str,
    times: &[f32],
    values: &[f32],
    comps: usize,
    joint: u16,
    w0: [f32; 4],
) -> PathBuf {
    use crate::common::gltf_builder::{Builder, Container, U16};
    use serde_json::json;
    let mut b = Builder::default();
    let p = b.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], 3, "VEC3");
    let i = b.indices(&[0, 1, 2], U16);
    let j = b.joints(&[[joint, 0, 0, 0], [0, 0, 0, 0], [0, 0, 0, 0]]);
    let w: Vec<f32> = w0
        .into_iter()
        .chain([1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0])
        .collect();
    let w = b.floats(&w, 4, "VEC4");
    let m = b.mesh(
        "tri",
        vec![json!({"attributes": {"POSITION": p, "JOINTS_0": j, "WEIGHTS_0": w}, "indices": i})],
    );
    b.node(json!({"mesh": m, "skin": 0}), true);
    b.node(json!({"name": "joint"}), true);
    b.skin(json!({"joints": [1]}));
    let t = b.data(times, 1, "SCALAR");
    let ty = if comps == 4 { "VEC4" } else { "VEC3" };
    let v = b.data(values, comps, ty);
    let path = if comps == 4 {
        "rotation"
    } else {
        "translation"
    };
    b.animation(json!({
        "samplers": [{"input": t, "output": v, "interpolation": "LINEAR"}],
        "channels": [{"sampler": 0, "target": {"node": 1, "path": path}}]
    }));
    b.write(&model_dir(), name, Container::Glb)
}

fn codes(scene: &Scene) -> Vec<&'static str> {
    scene.warnings.iter().map(|w| w.code).collect()
}

#[test]
fn bad_animation_data_is_refused_with_a_finding_never_a_panic() {
    let ok_w = [1.0, 0.0, 0.0, 0.0];
    let t3 = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0];
    // Times that do not increase, a NaN time, too few outputs, a NaN output.
    for (name, times, values) in [
        ("times_repeat", &[0.0f32, 0.0][..], &t3[..]),
        ("times_nan", &[0.0, f32::NAN][..], &t3[..]),
        ("outputs_short", &[0.0, 1.0][..], &t3[..3]),
        (
            "outputs_nan",
            &[0.0, 1.0][..],
            &[0.0, f32::NAN, 0.0, 1.0, 0.0, 0.0][..],
        ),
    ] {
        let scene = load_gltf(&broken(name, times, values, 3, 0, ok_w)).unwrap();
        assert!(
            codes(&scene).contains(&"ANIMATION_CHANNEL_INVALID"),
            "{name}: {:?}",
            codes(&scene)
        );
        let rig = scene.rig.as_ref().unwrap();
        assert!(
            rig.animations[0].channels.is_empty(),
            "{name}: the channel was kept"
        );
        // Posing with the channel dropped is the rest pose.
        let mut posed = scene.clone();
        posed.pose_at(&Playing::All, 0.5);
        assert_eq!(
            posed.meshes[0].primitives[0].positions,
            scene.meshes[0].primitives[0].positions
        );
    }
    // A joint index past the skin's one joint, and weights summing to 3.
    let t = [0.0, 1.0];
    let scene = load_gltf(&broken("joint_out_of_range", &t, &t3, 3, 5, ok_w)).unwrap();
    assert!(
        codes(&scene).contains(&"SKIN_JOINT_OUT_OF_RANGE"),
        "{:?}",
        codes(&scene)
    );
    let scene = load_gltf(&broken(
        "weights_sum_3",
        &t,
        &t3,
        3,
        0,
        [3.0, 0.0, 0.0, 0.0],
    ))
    .unwrap();
    assert!(
        codes(&scene).contains(&"SKIN_WEIGHTS_NOT_NORMALIZED"),
        "{:?}",
        codes(&scene)
    );
    let d = scene.meshes[0].primitives[0].deform.as_ref().unwrap();
    assert_eq!(d.weights[0], [1.0, 0.0, 0.0, 0.0]);
    // Huge keyframe counts: an input accessor claiming 10⁹ times is refused in one line.
    let p = broken("huge_input", &t, &t3, 3, 0, ok_w);
    let mut bytes = std::fs::read(&p).unwrap();
    let text = String::from_utf8_lossy(&bytes).to_string();
    let at = text.find("\"count\": 2,").expect("the input accessor");
    bytes.splice(at..at + 11, b"\"count\": 999999999,".iter().copied());
    let len = bytes.len() as u32;
    // The JSON chunk grew by 8 bytes (still 4-aligned): rewrite the GLB's lengths.
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) + 8;
    bytes[8..12].copy_from_slice(&len.to_le_bytes());
    bytes[12..16].copy_from_slice(&json_len.to_le_bytes());
    std::fs::write(&p, &bytes).unwrap();
    let e = load_gltf(&p)
        .expect_err("a 10⁹-key input is refused")
        .to_string();
    assert!(e.contains("past the end") && !e.contains('\n'), "{e}");
}
