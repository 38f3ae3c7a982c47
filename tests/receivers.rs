//! Small receivers drawn without the shadow lookup beyond the casters' reach
//! (`SceneOptions::receiver_split`, on by default on lavapipe) give the image drawn with the
//! lookup everywhere, pixel for pixel: under a low sun whose shadows fall far from their casters
//! on screen, under a spot light (a perspective reach with its apex), and in the demo scene.
//! Validation on.

use crate::common::*;
use glam::{Mat4, Vec3};
use umbra::plan::SceneOptions;
use umbra::scene::built::demo::demo_scene;
use umbra::scene::built::shapes::{add_object, colored, cuboid, uv_sphere};
use umbra::scene::{Camera, Light, LightKind, Scene};
use umbra::View;

fn render(ctx: &TestContext, scene: &Scene, split: bool, view: &View) -> umbra::RenderedFrame {
    let options = SceneOptions {
        receiver_split: Some(split),
        ..Default::default()
    };
    render_with(ctx, scene, &options, view, (320, 180))
}

/// Pixels that `shadows` draws darker than `no_shadows` by over 30 levels of luminance: the
/// shadows in the picture (the sky still lights them, bluish).
fn shadowed(shadows: &image::RgbaImage, no_shadows: &image::RgbaImage) -> usize {
    let luma =
        |p: &image::Rgba<u8>| 0.2126 * p[0] as f32 + 0.7152 * p[1] as f32 + 0.0722 * p[2] as f32;
    shadows
        .pixels()
        .zip(no_shadows.pixels())
        .filter(|(p, q)| luma(p) + 30.0 < luma(q))
        .count()
}

/// `view` without shadows.
fn unshadowed(view: &View) -> View {
    let mut v = view.clone();
    v.shadow.enabled = false;
    v
}

/// A 40-unit ground with two posts and a sphere, off to one side of the view.
fn posts(light: Light) -> Scene {
    let mut s = ground_scene(40.0, "posts");
    for (i, x) in [-3.0f32, 2.0].into_iter().enumerate() {
        add_object(
            &mut s,
            &format!("post {i}"),
            cuboid(Vec3::new(0.25, 2.0, 0.25)),
            colored(Vec3::new(0.7, 0.3, 0.2), 0.6),
            Mat4::from_translation(Vec3::new(x, 2.0, -2.0)),
        );
    }
    add_object(
        &mut s,
        "sphere",
        uv_sphere(0.8, 32, 16),
        colored(Vec3::new(0.2, 0.4, 0.8), 0.4),
        Mat4::from_translation(Vec3::new(0.0, 0.8, 1.0)),
    );
    s.lights.push(light);
    s
}

fn view_of_posts() -> View {
    let mut v = View::new(Camera::look_at(
        Vec3::new(1.0, 6.0, 12.0),
        Vec3::new(0.0, 0.5, 0.0),
        50f32.to_radians(),
        0.1,
    ));
    // One map (the split needs a single shadow view).
    v.shadow.cascades = 1;
    v
}

/// Renders `view` of `scene` with the split on and off and asserts the same image to the bit,
/// the ground alone split; saves the split image as `name`. Returns the shadowed pixels (against
/// the view without shadows), so a caller can check that the shadows are in the picture.
fn assert_unchanged(ctx: &TestContext, scene: &Scene, view: &View, name: &str) -> usize {
    let on = render(ctx, scene, true, view);
    let off = render(ctx, scene, false, view);
    save(&on.image, name);
    // Measured: 0 pixels differ in every scene here (beyond the reach the shadowed shader's
    // visibility is exactly 1).
    let n = image_diff(&on.image, &off.image).differing();
    assert_eq!(n, 0, "{name}: {n} pixels differ");
    assert_eq!(
        on.stats.unshadowed_draws, 1,
        "{name}: the ground alone is split"
    );
    assert_eq!(off.stats.unshadowed_draws, 0);
    let plain = render(ctx, scene, true, &unshadowed(view));
    let n = shadowed(&off.image, &plain.image);
    eprintln!("{name}: {n} shadowed pixels");
    n
}

/// A sun 20° above the horizon, from the side: the posts' shadows run ~11 units across the
/// ground, far from the posts on screen, so the reach's screen rectangle must follow the light,
/// not the casters.
#[test]
fn low_sun_shadows_unchanged_by_the_split() {
    let ctx = context();
    let scene = posts(Light::sun(
        Light::sun_direction(20f32.to_radians(), std::f32::consts::FRAC_PI_2),
        3.0,
    ));
    let n = assert_unchanged(&ctx, &scene, &view_of_posts(), "receivers_low_sun.png");
    // Measured: 1,012 shadowed pixels (two posts' and a sphere's shadows).
    assert!(n > 800, "{n} shadowed pixels");
    assert_validation_clean(&ctx);
}

/// A spot light above the scene: the reach is a frustum from the light; the ground beyond the
/// casters' rectangle in its view is drawn unshadowed, the image unchanged.
#[test]
fn spot_light_shadows_unchanged_by_the_split() {
    let ctx = context();
    let spot = Light {
        kind: LightKind::Spot {
            inner: 35f32.to_radians(),
            outer: 45f32.to_radians(),
        },
        position: Vec3::new(-2.0, 7.0, 3.0),
        direction: Vec3::new(0.3, -1.0, -0.6).normalize(),
        intensity: 150.0,
        ..Light::sun(Vec3::NEG_Y, 1.0)
    };
    let n = assert_unchanged(&ctx, &posts(spot), &view_of_posts(), "receivers_spot.png");
    // Measured: 555 shadowed pixels.
    assert!(n > 500, "{n} shadowed pixels");
    assert_validation_clean(&ctx);
}

/// The demo scene: its ground is split, its image unchanged.
#[test]
fn demo_unchanged_by_the_split() {
    let ctx = context();
    let scene = demo_scene();
    let n = assert_unchanged(
        &ctx,
        &scene,
        &View::new(scene.cameras[0]),
        "receivers_demo.png",
    );
    // Measured: 674 shadowed pixels.
    assert!(n > 550, "{n} shadowed pixels");
    assert_validation_clean(&ctx);
}
