//! Deferred shading of micro-triangle draws (`SceneOptions::deferred`, on by default on
//! lavapipe) gives the forward pass's image: textured, normal-mapped and texture-transformed
//! spheres of sub-pixel triangles under a shadowing sun and a point light, beside draws that
//! stay forward (a vertex-coloured sphere, the ground). Validation on.

use crate::common::*;
use glam::{Mat4, Vec2, Vec3, Vec4};
use umbra::plan::SceneOptions;
use umbra::scene::built::shapes::{add_object, add_texture, colored, quad, uv_sphere};
use umbra::scene::built::synthetic::double_sided_scene;
use umbra::scene::{Camera, Light, LightKind, Material, Scene, Texture, TextureRef, UvTransform};
use umbra::{Renderer, View};

fn render(ctx: &TestContext, scene: &Scene, deferred: bool, view: &View) -> umbra::RenderedFrame {
    render_at(ctx, scene, deferred, view, (320, 180))
}

fn render_at(
    ctx: &TestContext,
    scene: &Scene,
    deferred: bool,
    view: &View,
    size: (u32, u32),
) -> umbra::RenderedFrame {
    let options = SceneOptions {
        deferred: Some(deferred),
        ..Default::default()
    };
    render_with(ctx, scene, &options, view, size)
}

/// A 64×64 texture from `f(x, y)`.
fn texture(name: &str, f: impl Fn(u32, u32) -> [u8; 4]) -> Texture {
    Texture {
        name: name.into(),
        width: 64,
        height: 64,
        rgba: (0..64 * 64).flat_map(|i| f(i % 64, i / 64)).collect(),
        ktx2: None,
    }
}

/// Three textured spheres of ~9 k triangles each (a checker base colour, a normal map of ridges,
/// metallic-roughness; one with a rotated, scaled texture transform), a vertex-coloured sphere
/// and the ground; a sun and a point light.
fn micro_scene() -> Scene {
    let mut s = Scene::default();
    let checker = add_texture(
        &mut s,
        texture("checker", |x, y| {
            let v = if (x / 8 + y / 8) % 2 == 0 { 230 } else { 40 };
            [v, 128, 255 - v, 255]
        }),
    );
    let ridges = add_texture(
        &mut s,
        texture("ridges", |x, y| {
            let wave = |c: u32, k: f32| (c as f32 / 64.0 * std::f32::consts::TAU * k).sin();
            let n = Vec3::new(0.6 * wave(x, 4.0), 0.5 * wave(y, 3.0), 1.0).normalize();
            let b = |c: f32| ((c * 0.5 + 0.5) * 255.0).round() as u8;
            [b(n.x), b(n.y), b(n.z), 255]
        }),
    );
    let mr = add_texture(
        &mut s,
        texture("metal-rough", |x, y| {
            [255, 40 + (x * 3) as u8, (y * 4) as u8, 255]
        }),
    );
    for (i, x) in [-1.2f32, 0.0, 1.2].into_iter().enumerate() {
        let mut base = TextureRef::new(checker);
        if i == 2 {
            base.transform = UvTransform {
                offset: Vec2::new(0.25, 0.1),
                rotation: 0.7,
                scale: Vec2::new(3.0, 1.5),
            };
        }
        let m = Material {
            name: format!("textured {i}"),
            base_color_texture: Some(base),
            normal_texture: Some(TextureRef::new(ridges)),
            metallic_roughness_texture: Some(TextureRef::new(mr)),
            roughness: 0.6,
            ..Default::default()
        };
        add_object(
            &mut s,
            &format!("sphere {i}"),
            uv_sphere(0.5, 96, 48),
            m,
            Mat4::from_translation(Vec3::new(x, 0.5, 0.0)),
        );
    }
    let mut painted = uv_sphere(0.5, 96, 48);
    painted.colors = painted
        .positions
        .iter()
        .map(|p| Vec4::new(0.5 + p.x, 0.5 + p.y, 0.5 - p.z, 1.0))
        .collect();
    add_object(
        &mut s,
        "vertex-coloured sphere",
        painted,
        colored(Vec3::ONE, 0.5),
        Mat4::from_translation(Vec3::new(0.6, 0.5, -1.3)),
    );
    add_object(
        &mut s,
        "ground",
        quad(8.0, 8.0),
        colored(Vec3::splat(0.6), 0.9),
        Mat4::from_rotation_x(-std::f32::consts::FRAC_PI_2),
    );
    s.lights
        .push(Light::sun(Light::sun_direction(0.8, 0.6), 3.0));
    s.lights.push(Light {
        kind: LightKind::Point,
        position: Vec3::new(-1.0, 2.0, 1.5),
        color: Vec3::new(1.0, 0.8, 0.6),
        intensity: 6.0,
        ..Light::sun(Vec3::NEG_Y, 1.0)
    });
    s
}

/// The micro scene's view: the four spheres and the ground from above and in front.
fn micro_view() -> View {
    View::new(Camera::look_at(
        Vec3::new(0.0, 2.0, 5.0),
        Vec3::new(0.0, 0.4, 0.0),
        45f32.to_radians(),
        0.1,
    ))
}

/// The micro scene's view at `size`, deferred and forward (saved as `name`.png and
/// `name`_forward.png): exactly the three textured spheres deferred, nothing forward, the same
/// draws; returns (largest channel difference, pixels differing by more than 2 levels).
fn micro_deferred_against_forward(ctx: &TestContext, size: (u32, u32), name: &str) -> (u8, usize) {
    let scene = micro_scene();
    let view = micro_view();
    let on = render_at(ctx, &scene, true, &view, size);
    let off = render_at(ctx, &scene, false, &view, size);
    save(&on.image, &format!("{name}.png"));
    save(&off.image, &format!("{name}_forward.png"));
    assert_eq!(
        on.stats.deferred_draws, 3,
        "the three textured spheres are deferred, nothing else"
    );
    assert_eq!(off.stats.deferred_draws, 0);
    assert_eq!(on.stats.draws, off.stats.draws);
    let d = image_diff(&on.image, &off.image);
    let (largest, changed) = (d.largest(), d.over(2));
    eprintln!(
        "deferred vs forward at {}x{}: largest difference {largest} levels, {changed} pixels > 2",
        size.0, size.1
    );
    (largest, changed)
}

/// The spheres' triangles cover well under a pixel at 320×180, so they are deferred (and the
/// vertex-coloured sphere and the ground are not); the image is the forward pass's.
#[test]
fn deferred_micro_triangles_give_the_forward_image() {
    let ctx = context();
    let (largest, changed) = micro_deferred_against_forward(&ctx, (320, 180), "deferred_micro");
    // Measured: largest 5 levels, 7 pixels over 2, all on silhouettes: llvmpipe computes one
    // mip level per 2×2 quad, explicit derivatives included, so a silhouette pixel whose quad
    // also holds another surface can read a level of its derivatives (the forward pass
    // extrapolates its own triangle). Everywhere else the resolve reads the same varyings (directions through
    // 16-bit octahedral codes, derivatives through f16): at most 2 levels.
    assert!(largest <= 8, "largest difference {largest} levels");
    assert!(
        changed <= 12,
        "{changed} pixels differ by more than 2 levels"
    );
    assert_validation_clean(&ctx);
}

/// At 1280×720 the textured spheres' triangles average about 5 pixels (llvmpipe still shades
/// about twice the lanes it keeps around them): they are deferred too, and match the forward
/// image.
#[test]
fn deferred_few_pixel_triangles_give_the_forward_image() {
    let ctx = context();
    let (largest, changed) =
        micro_deferred_against_forward(&ctx, (1280, 720), "deferred_few_pixels");
    // Measured: largest 20 levels, 14 pixels over 2 (633 of 921,600 by any), all on the spheres'
    // silhouettes against the ground (one mip level per 2×2 quad, as above).
    assert!(largest <= 24, "largest difference {largest} levels");
    assert!(
        changed <= 18,
        "{changed} pixels differ by more than 2 levels"
    );
    assert_validation_clean(&ctx);
}

/// The double-sided benchmark scene (its spheres deferred at this size) matches too.
#[test]
fn deferred_double_sided_scene_matches_forward() {
    let ctx = context();
    let scene = double_sided_scene();
    let view = View::new(scene.cameras[0]);
    let on = render(&ctx, &scene, true, &view);
    let off = render(&ctx, &scene, false, &view);
    save(&on.image, "deferred_double_sided.png");
    assert!(
        on.stats.deferred_draws >= 8,
        "{} draws deferred",
        on.stats.deferred_draws
    );
    let d = image_diff(&on.image, &off.image);
    let (largest, changed) = (d.largest(), d.over(2));
    eprintln!("double-sided: largest difference {largest} levels, {changed} pixels > 2");
    // Measured: largest 1 level, 0 pixels over 2.
    assert!(largest <= 3, "largest difference {largest} levels");
    assert_eq!(changed, 0, "{changed} pixels differ by more than 2 levels");
    assert_validation_clean(&ctx);
}

/// The close-up stand-in at 1280×720: its open double-sided models, triangles of about 50
/// pixels, defer because they overdraw themselves (`deferred::overdraws_itself`), its flat ground
/// stays forward, and the image matches the forward one. On a CPU device the ground reads its
/// uniforms as flat inputs (`fs_main_flat`, triangles of over 16 pixels), as the resolves do;
/// drawn forward, so do the four models whose triangles `pixels_per_triangle` puts at 16 pixels
/// or more.
#[test]
fn open_double_sided_models_defer_at_a_close_view_and_match_forward() {
    let ctx = context();
    let scene = umbra::scene::built::synthetic::close_up_scene();
    let view = View::new(scene.cameras[0]);
    let on = render_at(&ctx, &scene, true, &view, (1280, 720));
    let off = render_at(&ctx, &scene, false, &view, (1280, 720));
    save(&on.image, "deferred_close_up.png");
    assert_eq!(on.stats.deferred_draws, 11, "the 11 models, not the ground");
    assert_eq!(off.stats.deferred_draws, 0);
    if ctx.is_cpu() {
        assert_eq!(on.stats.flat_draws, 1, "the ground");
        assert_eq!(off.stats.flat_draws, 5, "the ground and four models");
    }
    let d = image_diff(&on.image, &off.image);
    let (largest, changed) = (d.largest(), d.over(2));
    eprintln!("close-up: largest difference {largest} levels, {changed} pixels > 2");
    // Measured: largest 1 level (1,537 pixels), 0 pixels over 2.
    assert!(largest <= 2, "largest difference {largest} levels");
    assert_eq!(changed, 0, "{changed} pixels differ by more than 2 levels");
    assert_validation_clean(&ctx);
}

/// A deferred frame does not depend on what the frame before it left in the G-buffer: the
/// micro scene's view rendered after another view equals the same view from a fresh renderer,
/// pixel for pixel.
#[test]
fn deferred_frames_do_not_depend_on_the_previous_frame() {
    let ctx = context();
    let scene = micro_scene();
    let target = micro_view();
    let other = View::new(Camera::look_at(
        Vec3::new(1.5, 1.0, 3.0),
        Vec3::new(0.0, 0.5, 0.0),
        35f32.to_radians(),
        0.1,
    ));
    let options = SceneOptions {
        deferred: Some(true),
        ..Default::default()
    };
    let fresh = Renderer::with_options(&ctx, &scene, &options)
        .unwrap()
        .render(&target, 320, 180)
        .unwrap();
    let mut r = Renderer::with_options(&ctx, &scene, &options).unwrap();
    let before = r.render(&other, 320, 180).unwrap();
    let after = r.render(&target, 320, 180).unwrap();
    assert!(before.stats.deferred_draws > 0 && after.stats.deferred_draws > 0);
    let differing = fresh
        .image
        .pixels()
        .zip(after.image.pixels())
        .filter(|(p, q)| p != q)
        .count();
    // Measured: 0; with the G-buffer pass loading depth and stencil instead of clearing them,
    // 32,777.
    assert_eq!(
        differing, 0,
        "{differing} pixels depend on the previous frame"
    );
    drop(r);
    assert_validation_clean(&ctx);
}
