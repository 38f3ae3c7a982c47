//! Per-pixel outputs besides the image (`Renderer::render_aovs`, lavapipe, validation on): a
//! plane facing the camera reads its distance along the view axis to 1e-4 and 0 off it, under a
//! perspective and an orthographic camera; two instances read their own ids exactly, the
//! background 0; normals face the camera; an alpha-masked cut-out reads what lies behind it.

use crate::common::*;
use glam::{Mat4, Vec3, Vec4};
use umbra::plan::View;
use umbra::render::Renderer;
use umbra::scene::built::shapes::{add_object, add_texture, colored, quad};
use umbra::scene::{AlphaMode, Camera, Material, Scene, Texture, TextureRef};

const W: u32 = 160;
const H: u32 = 120;

/// A 2 × 2 quad at z = 0 facing +Z (instance 0), and a small one at z = 1 on its right (instance
/// 1), whose left half is cut out by an alpha mask.
fn scene() -> Scene {
    let mut s = Scene {
        name: "aov".into(),
        ..Default::default()
    };
    add_object(
        &mut s,
        "back",
        quad(2.0, 2.0),
        colored(Vec3::splat(0.5), 0.5),
        Mat4::IDENTITY,
    );
    let alpha = add_texture(
        &mut s,
        Texture {
            name: "half".into(),
            width: 2,
            height: 1,
            rgba: vec![255, 255, 255, 0, 255, 255, 255, 255],
            ktx2: None,
        },
    );
    let mut cut = colored(Vec3::new(0.9, 0.2, 0.1), 0.5);
    cut.alpha_mode = AlphaMode::Mask(0.5);
    cut.base_color_texture = Some(TextureRef {
        sampler: umbra::scene::Sampler {
            mag: umbra::scene::Filter::Nearest,
            min: umbra::scene::Filter::Nearest,
            ..Default::default()
        },
        ..TextureRef::new(alpha)
    });
    add_object(
        &mut s,
        "front",
        quad(0.5, 0.5),
        Material { ..cut },
        Mat4::from_translation(Vec3::new(0.5, 0.0, 1.0)),
    );
    s
}

#[test]
fn depth_ids_and_normals_read_what_the_geometry_says() {
    let ctx = context();
    let s = scene();
    let mut r = Renderer::new(&ctx, &s).unwrap();
    for (name, camera) in [
        (
            "perspective",
            Camera::look_at(
                Vec3::new(0.0, 0.0, 5.0),
                Vec3::ZERO,
                45f32.to_radians(),
                0.1,
            ),
        ),
        (
            "orthographic",
            Camera::orthographic_look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, 1.5, 0.1, 20.0),
        ),
    ] {
        let a = r.render_aovs(&View::new(camera), W, H).unwrap();
        let at = |x: u32, y: u32| (y * W + x) as usize;
        // Project a world point to its pixel with the plan's matrix.
        let px = |p: Vec3| {
            let c = a.plan.clip_from_world * Vec4::new(p.x, p.y, p.z, 1.0);
            let n = c.truncate().truncate() / c.w;
            (
                ((n.x * 0.5 + 0.5) * W as f32) as u32,
                ((0.5 - n.y * 0.5) * H as f32) as u32,
            )
        };
        // The back quad at (-0.6, 0.4): 5 units along the view axis.
        let (x, y) = px(Vec3::new(-0.6, 0.4, 0.0));
        let d = a.depth[at(x, y)];
        assert!((d - 5.0).abs() < 5e-4, "{name}: back quad at {d}");
        assert_eq!(a.instance[at(x, y)], 1, "{name}");
        let n = Vec3::from_array(a.normal[at(x, y)]);
        assert!(n.abs_diff_eq(Vec3::Z, 1e-5), "{name}: normal {n}");
        // The front quad's kept (right) half: 4 units, instance 1 + 1.
        let (x, y) = px(Vec3::new(0.65, 0.0, 1.0));
        let d = a.depth[at(x, y)];
        assert!((d - 4.0).abs() < 4e-4, "{name}: front quad at {d}");
        assert_eq!(a.instance[at(x, y)], 2, "{name}");
        // Its cut-out (left) half shows the back quad.
        let (x, y) = px(Vec3::new(0.35, 0.0, 1.0));
        assert_eq!(
            a.instance[at(x, y)],
            1,
            "{name}: the cut-out is not see-through"
        );
        assert!((a.depth[at(x, y)] - 5.0).abs() < 5e-4, "{name}");
        // Off the quads: nothing.
        let (x, y) = px(Vec3::new(1.4, 1.2, 0.0));
        assert_eq!(
            (a.instance[at(x, y)], a.depth[at(x, y)], a.normal[at(x, y)]),
            (0, 0.0, [0.0; 3]),
            "{name}"
        );
        let ids = a.instance.iter().filter(|&&i| i == 2).count();
        eprintln!("{name}: {ids} pixels of the front quad's kept half");
        // Each output read alone is the same array, the others left empty.
        for (i, set) in [
            (true, false, false),
            (false, true, false),
            (false, false, true),
        ]
        .into_iter()
        .enumerate()
        {
            let (instance, normal, depth) = set;
            let set = umbra::render::AovSet {
                instance,
                normal,
                depth,
            };
            let b = r.render_aovs_of(&View::new(camera), W, H, set).unwrap();
            let lens = [b.instance.len(), b.normal.len(), b.depth.len()];
            let want: [usize; 3] =
                std::array::from_fn(|k| if k == i { (W * H) as usize } else { 0 });
            assert_eq!(lens, want, "{name}: {set:?}");
            assert!(
                b.instance == a.instance || !instance,
                "{name}: ids alone differ"
            );
            assert!(
                b.normal == a.normal || !normal,
                "{name}: normals alone differ"
            );
            assert!(b.depth == a.depth || !depth, "{name}: depth alone differs");
        }
    }
    drop(r);
    assert_validation_clean(&ctx);
}

/// The close-up stand-in (`--synthetic close-up`) is what it claims: at its own camera, 1280×720,
/// its models (every instance but the ground) cover about a third of the frame, as the C++
/// sample's models do at the sample's camera.
#[test]
fn close_up_models_cover_a_third_of_the_frame() {
    let ctx = context();
    let scene = umbra::scene::built::synthetic::close_up_scene();
    let mut r = Renderer::new(&ctx, &scene).unwrap();
    let (w, h) = (640, 360);
    let view = View::new(scene.cameras[0]);
    let a = r.render_aovs(&view, w, h).unwrap();
    let models = a.instance.iter().filter(|&&i| i > 1).count();
    let share = models as f64 / (w * h) as f64;
    eprintln!("close-up: models cover {:.1} % of the frame", share * 100.0);
    // Measured: 33.4 %.
    assert!((0.30..0.37).contains(&share), "{:.3}", share);
    drop(r);
}

/// `render_with_aovs` at one sample per pixel draws the ids and normals in the camera pass
/// itself, and what it returns is what two calls return: the image of `render` to the byte, and
/// the ids, normals and depth of the AOV pass (`render_aovs_of`) to the bit. Over the masked
/// cut-out, the demo (sky, normal maps), blended and masked foliage, a sphere grid whose
/// micro-triangles go through the G-buffer (deferred draws), and FlightHelmet when the extra
/// corpus is there.
#[test]
fn camera_pass_aovs_are_the_aov_pass_and_the_image_is_unchanged() {
    use umbra::render::AovSet;
    use umbra::scene::built;
    let ctx = context();
    let mut cases: Vec<(String, Scene)> = vec![
        ("aov".into(), scene()),
        ("demo".into(), built::demo::demo_scene()),
        (
            "foliage blend".into(),
            built::foliage::foliage_scene(AlphaMode::Blend),
        ),
        ("spheres 8".into(), built::synthetic::sphere_grid(8)),
    ];
    if let Some(extra) = crate::common::corpus::extra_corpus() {
        let path = extra.join("FlightHelmet/FlightHelmet.gltf");
        if let Ok(mut s) = umbra::scene::gltf::load_gltf(&path) {
            built::shapes::add_ground(&mut s);
            cases.push(("FlightHelmet".into(), s));
        }
    }
    let (w, h) = (200, 150);
    let mut deferred_seen = false;
    for (name, scene) in &cases {
        let mut r = Renderer::new(&ctx, scene).unwrap();
        let view = View::new(scene.default_camera(w as f32 / h as f32));
        for set in [
            AovSet::ALL,
            AovSet {
                instance: true,
                normal: false,
                depth: false,
            },
            // The ids' target unbound (its writes discarded), the normals drawn.
            AovSet {
                instance: false,
                normal: true,
                depth: true,
            },
        ] {
            // The targets first hold another view's ids and normals (turned around), so that
            // one the pass should draw and does not cannot pass for drawn.
            let mut away = view.clone();
            away.camera.world_from_view *= Mat4::from_rotation_y(std::f32::consts::PI);
            r.render_with_aovs(&away, w, h, AovSet::ALL).unwrap();
            let (frame, aovs) = r.render_with_aovs(&view, w, h, set).unwrap();
            assert!(
                frame.stats.aovs_in_camera_pass,
                "{name}: drawn by the AOV pass"
            );
            deferred_seen |= frame.stats.deferred_draws > 0;
            let image = r.render(&view, w, h).unwrap().image;
            assert!(frame.image == image, "{name}: the image changed");
            let pass = r.render_aovs_of(&view, w, h, set).unwrap();
            assert!(aovs.instance == pass.instance, "{name}: ids differ");
            assert!(aovs.normal == pass.normal, "{name}: normals differ");
            assert!(aovs.depth == pass.depth, "{name}: depths differ");
            assert!(
                !set.instance || aovs.instance.iter().any(|&i| i > 0),
                "{name}: no ids"
            );
            assert!(
                !set.normal || aovs.normal.iter().any(|n| n.iter().any(|c| c.abs() > 0.5)),
                "{name}: no normals"
            );
        }
    }
    assert!(deferred_seen, "no case drew deferred");
    assert_validation_clean(&ctx);
}
