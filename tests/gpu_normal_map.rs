//! Normal mapping on lavapipe (validation on): a bump-mapped panel lit from the left is brighter
//! on its left-facing slopes, with stored tangents, with mirrored UVs (tangent w = −1), and with
//! MikkTSpace-generated tangents.

use crate::common::*;
use glam::{Mat4, Vec2, Vec3};
use umbra::plan::View;
use umbra::render::Renderer;
use umbra::scene::built::demo::bump_normal_map;
use umbra::scene::built::shapes::{add_object, add_texture, quad};
use umbra::scene::mesh::mikk::generate_mikktspace;
use umbra::scene::{Camera, Light, Material, Primitive, Scene, TextureRef};

const BUMPS: u32 = 4;
const SIZE: u32 = 160;

fn panel_scene(p: Primitive) -> Scene {
    panel_scene_lit(p, Vec3::new(1.0, 0.0, -0.6))
}

fn panel_scene_lit(mut p: Primitive, light: Vec3) -> Scene {
    let mut s = Scene {
        name: "bump panel".into(),
        ..Default::default()
    };
    let tex = add_texture(&mut s, bump_normal_map(256, BUMPS, 1.5));
    let m = Material {
        normal_texture: Some(TextureRef::new(tex)),
        roughness: 1.0,
        ..Default::default()
    };
    p.material = 0;
    add_object(&mut s, "panel", p, m, Mat4::IDENTITY);
    // Default: light from the left, grazing: travels towards +X and into the panel.
    s.lights.push(Light::sun(light.normalize(), 1.0));
    s
}

/// Mean luminance of pixels on left-facing slopes minus that on right-facing slopes. The panel
/// fills the view exactly, so pixel x maps to u (or 1 − u when mirrored) linearly.
fn slope_contrast(img: &image::RgbaImage) -> f32 {
    axis_contrast(img, false)
}

/// Mean luminance of up-facing minus down-facing slopes (pixel y maps to v).
fn vertical_contrast(img: &image::RgbaImage) -> f32 {
    axis_contrast(img, true)
}

fn axis_contrast(img: &image::RgbaImage, vertical: bool) -> f32 {
    let k = std::f32::consts::PI * BUMPS as f32;
    let (mut left, mut nl, mut right, mut nr) = (0.0, 0, 0.0, 0);
    for (x, y, p) in img.enumerate_pixels() {
        let u = if vertical {
            (y as f32 + 0.5) / img.height() as f32
        } else {
            (x as f32 + 0.5) / img.width() as f32
        };
        // Slope of h = sin²(k u)·…: rising to the right faces left; rising downwards faces up.
        let s = (2.0 * k * u).sin();
        let l = p[0] as f32;
        if s > 0.5 {
            left += l;
            nl += 1;
        } else if s < -0.5 {
            right += l;
            nr += 1;
        }
    }
    left / nl as f32 - right / nr as f32
}

fn render(scene: &Scene) -> image::RgbaImage {
    let ctx = context();
    let mut r = Renderer::new(&ctx, scene).unwrap();
    // The 2×2 panel exactly fills a square view at distance 1/tan(fov/2).
    let fov = 60f32.to_radians();
    let cam = Camera::look_at(
        Vec3::new(0.0, 0.0, 1.0 / (fov * 0.5).tan()),
        Vec3::ZERO,
        fov,
        0.01,
    );
    let mut v = View::new(cam);
    v.shadow.enabled = false;
    let f = r.render(&v, SIZE, SIZE).unwrap();
    assert_validation_clean(&ctx);
    f.image
}

fn mirrored(mut p: Primitive) -> Primitive {
    for uv in &mut p.uvs {
        *uv = Vec2::new(1.0 - uv.x, uv.y);
    }
    for t in &mut p.tangents {
        *t = glam::Vec4::new(-t.x, -t.y, -t.z, -t.w);
    }
    p
}

#[test]
fn bumps_are_brighter_on_slopes_facing_the_light() {
    let img = render(&panel_scene(quad(2.0, 2.0)));
    save(&img, "bumps.png");
    let c = slope_contrast(&img);
    assert!(
        c > 20.0,
        "left-facing slopes should be brighter: contrast {c}"
    );
    // Without the normal map the panel is flat: no contrast.
    let mut flat = panel_scene(quad(2.0, 2.0));
    flat.materials[0].normal_texture = None;
    let c0 = slope_contrast(&render(&flat));
    assert!(c0.abs() < 1.0, "flat panel contrast {c0}");
}

#[test]
fn mirrored_uvs_light_the_same_way() {
    let img = render(&panel_scene(mirrored(quad(2.0, 2.0))));
    save(&img, "bumps_mirrored.png");
    let c = slope_contrast(&img);
    assert!(
        c > 20.0,
        "mirrored UVs (tangent w = -1) must light like the original: contrast {c}"
    );
}

#[test]
fn mikktspace_tangents_light_the_same_way() {
    for (name, mut p) in [
        ("plain", quad(2.0, 2.0)),
        ("mirrored", mirrored(quad(2.0, 2.0))),
    ] {
        p.tangents.clear();
        assert!(generate_mikktspace(&mut p));
        let img = render(&panel_scene(p));
        save(&img, &format!("bumps_mikk_{name}.png"));
        let c = slope_contrast(&img);
        assert!(
            c > 20.0,
            "{name}: generated tangents must light like stored ones: contrast {c}"
        );
    }
}

#[test]
fn bitangent_sign_with_light_from_above() {
    // Light from above exercises the bitangent, i.e. tangent.w: with stored tangents, mirrored
    // UVs (w = −1) and generated ones, up-facing slopes must be the brighter ones.
    let light = Vec3::new(0.0, -1.0, -0.6);
    let mut generated = mirrored(quad(2.0, 2.0));
    generated.tangents.clear();
    assert!(generate_mikktspace(&mut generated));
    for (name, p) in [
        ("plain", quad(2.0, 2.0)),
        ("mirrored", mirrored(quad(2.0, 2.0))),
        ("mikk mirrored", generated),
    ] {
        let img = render(&panel_scene_lit(p, light));
        save(&img, &format!("bumps_above_{}.png", name.replace(' ', "_")));
        let c = vertical_contrast(&img);
        assert!(
            c > 20.0,
            "{name}: up-facing slopes should be brighter under light from above: contrast {c}"
        );
    }
    // A wrong sign would show: flipping w on the stored tangents inverts the contrast.
    let mut wrong = quad(2.0, 2.0);
    for t in &mut wrong.tangents {
        t.w = -t.w;
    }
    let c = vertical_contrast(&render(&panel_scene_lit(wrong, light)));
    assert!(
        c < -20.0,
        "a flipped bitangent must invert the contrast: {c}"
    );
}
