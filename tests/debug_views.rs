//! The debug views (`render --view`, the viewer's `V` cycle) on lavapipe with validation on, each
//! checked for what it must show: the UV checker's cell count on a unit quad, tangents along +u
//! and bitangents up the image, the material's base colour / metallic / roughness as bytes,
//! depth darkening with distance, shadow texel density brighter near the camera, the cascade
//! index rising with depth, and overdraw counting layers.

use crate::common::*;
use glam::{Mat4, Vec3};
use umbra::plan::{View, ViewMode};
use umbra::render::{RenderedFrame, Renderer};
use umbra::scene::built::shapes::{add_object, colored, cuboid, plane, quad};
use umbra::scene::built::synthetic::town_scene;
use umbra::scene::{Camera, Material, Scene};

const SIZE: u32 = 160;

/// A unit quad facing +Z at the origin with `material`, seen head-on from 2 units away.
fn quad_scene(material: Material) -> (Scene, View) {
    let mut s = Scene {
        name: "quad".into(),
        ..Default::default()
    };
    add_object(&mut s, "quad", quad(1.0, 1.0), material, Mat4::IDENTITY);
    let cam = Camera::look_at(
        Vec3::new(0.0, 0.0, 2.0),
        Vec3::ZERO,
        40f32.to_radians(),
        0.01,
    );
    (s, View::new(cam))
}

fn render(ctx: &TestContext, scene: &Scene, view: &View, mode: ViewMode) -> RenderedFrame {
    let mut r = Renderer::new(ctx, scene).unwrap();
    let mut v = view.clone();
    v.mode = mode;
    let f = r.render(&v, SIZE, SIZE).unwrap();
    save(&f.image, &format!("debug_{mode:?}.png"));
    f
}

fn save(img: &image::RgbaImage, name: &str) {
    img.save(out_dir().join(name)).unwrap();
}

fn px(f: &RenderedFrame, x: u32, y: u32) -> [u8; 4] {
    f.image.get_pixel(x, y).0
}

fn luma(p: [u8; 4]) -> f64 {
    0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64
}

fn close(a: [u8; 4], b: [u8; 3], tol: i32) -> bool {
    (0..3).all(|i| (a[i] as i32 - b[i] as i32).abs() <= tol)
}

/// Cells along a line of pixels of the checker (bytes 38 and 217; anything else is off the
/// quad): runs of one value.
fn checker_runs(line: impl Iterator<Item = [u8; 4]>) -> usize {
    let mut runs = 0;
    let mut last = None;
    for p in line {
        // Grey only (the background is 39, 39, 44).
        let v = match (p[0], p[0] == p[2]) {
            (36..=40, true) => 0,
            (215..=219, true) => 1,
            _ => continue,
        };
        if last != Some(v) {
            runs += 1;
            last = Some(v);
        }
    }
    runs
}

#[test]
fn uv_checker_has_eight_cells_per_unit_on_a_unit_quad() {
    let ctx = context();
    let (s, v) = quad_scene(colored(Vec3::ONE, 0.5));
    let f = render(&ctx, &s, &v, ViewMode::UvChecker);
    let mid = SIZE / 2 + 3; // off the cell boundary at v = 0.5
    let across = checker_runs((0..SIZE).map(|x| px(&f, x, mid)));
    let down = checker_runs((0..SIZE).map(|y| px(&f, mid, y)));
    assert_eq!((across, down), (8, 8));
    assert_validation_clean(&ctx);
}

#[test]
fn tangents_run_along_u_and_bitangents_up_the_image() {
    let ctx = context();
    let (s, v) = quad_scene(colored(Vec3::ONE, 0.5));
    let c = SIZE / 2;
    // +X → (255, 128, 128) (the shader encodes t·0.5+0.5; 127.5 rounds either way).
    let t = px(&render(&ctx, &s, &v, ViewMode::Tangents), c, c);
    assert!(close(t, [255, 128, 128], 1), "{t:?}");
    // The quad's bitangent w·(n × t) = +Y.
    let b = px(&render(&ctx, &s, &v, ViewMode::Bitangents), c, c);
    assert!(close(b, [128, 255, 128], 1), "{b:?}");
    assert_validation_clean(&ctx);
}

#[test]
fn base_colour_metallic_and_roughness_show_the_material() {
    let ctx = context();
    let m = Material {
        base_color: glam::Vec4::new(0.5, 0.25, 0.1, 1.0),
        metallic: 0.3,
        roughness: 0.7,
        ..Default::default()
    };
    let (s, v) = quad_scene(m);
    let c = SIZE / 2;
    // Linear 0.5, 0.25, 0.1 stored as sRGB bytes: 188, 137, 89.
    let b = px(&render(&ctx, &s, &v, ViewMode::BaseColor), c, c);
    assert!(close(b, [188, 137, 89], 1), "{b:?}");
    let m = px(&render(&ctx, &s, &v, ViewMode::Metallic), c, c);
    assert!(close(m, [77, 77, 77], 1), "metallic 0.3: {m:?}");
    let r = px(&render(&ctx, &s, &v, ViewMode::Roughness), c, c);
    assert!(close(r, [179, 179, 179], 1), "roughness 0.7: {r:?}");
    // Background stays the clear colour.
    assert_eq!(
        px(&render(&ctx, &s, &v, ViewMode::Metallic), 0, 0)[..3],
        [39, 39, 44]
    );
    assert_validation_clean(&ctx);
}

/// A 40 m ground with a box on it, seen from 1.7 m up looking along it.
fn ground_scene() -> (Scene, View) {
    let mut s = Scene {
        name: "ground".into(),
        ..Default::default()
    };
    add_object(
        &mut s,
        "ground",
        plane(40.0, 1.0),
        colored(Vec3::splat(0.5), 0.9),
        Mat4::IDENTITY,
    );
    add_object(
        &mut s,
        "box",
        cuboid(Vec3::splat(0.5)),
        colored(Vec3::splat(0.8), 0.5),
        Mat4::from_translation(Vec3::new(3.0, 0.5, -6.0)),
    );
    let cam = Camera::look_at(
        Vec3::new(0.0, 1.7, 8.0),
        Vec3::new(0.0, 0.0, -10.0),
        50f32.to_radians(),
        0.05,
    );
    (s, View::new(cam))
}

/// Mean luminance of the ground's pixels in rows `rows` of the centre column ±8.
fn band_luma(f: &RenderedFrame, rows: std::ops::Range<u32>) -> f64 {
    let (mut sum, mut n) = (0.0, 0);
    for y in rows {
        for x in SIZE / 2 - 8..SIZE / 2 + 8 {
            sum += luma(px(f, x, y));
            n += 1;
        }
    }
    sum / n as f64
}

#[test]
fn depth_darkens_with_distance() {
    let ctx = context();
    let (s, v) = ground_scene();
    let f = render(&ctx, &s, &v, ViewMode::Depth);
    // Ground from the bottom row up to the horizon (row ~50 of 160): darker every 16 rows.
    let bands: Vec<f64> = (0..5)
        .map(|i| band_luma(&f, SIZE - 16 * (i + 1)..SIZE - 16 * i))
        .collect();
    for w in bands.windows(2) {
        assert!(w[1] < w[0] - 5.0, "depth bands from near to far: {bands:?}");
    }
    assert_validation_clean(&ctx);
}

#[test]
fn texel_density_is_brighter_near_the_camera() {
    let ctx = context();
    let (s, mut v) = ground_scene();
    v.shadow.cascades = 1;
    let f = render(&ctx, &s, &v, ViewMode::TexelDensity);
    save(&f.image, "debug_TexelDensity_single_map.png");
    // One map over the view: a texel spans more pixels near the eye. Measured luminance near
    // 142.2, far 34.4 (with the ramp reversed: 200.2 and 249.6, and this fails).
    let near = band_luma(&f, SIZE - 16..SIZE);
    let far = band_luma(&f, SIZE - 80..SIZE - 64); // the ground ends at row ~74
    eprintln!("texel density: near {near:.1}, far {far:.1}");
    assert!(near > far + 80.0, "near {near:.1}, far {far:.1}");
    // Without shadows: mid grey everywhere on the ground.
    v.shadow.enabled = false;
    let off = render(&ctx, &s, &v, ViewMode::TexelDensity);
    assert!(close(px(&off, SIZE / 2, SIZE - 4), [128, 128, 128], 1));
    assert_validation_clean(&ctx);
}

#[test]
fn cascade_index_rises_with_depth() {
    let ctx = context();
    let scene = town_scene();
    // From the roof, looking down the street (from eye height the far cascades squeeze into a
    // few rows under the horizon).
    let mut v = View::new(scene.cameras[1]);
    v.shadow.cascades = 4;
    v.mode = ViewMode::Cascades;
    let mut r = Renderer::new(&ctx, &scene).unwrap();
    let (w, h) = (320, 180);
    let f = r.render(&v, w, h).unwrap();
    save(&f.image, "debug_cascades_town.png");
    // Each row's most common cascade (by hue: red, green, blue, yellow) up the centre column
    // from the bottom; dithered blend bands mix neighbours, so the mode of each band of rows.
    let cascade = |p: [u8; 4]| -> Option<usize> {
        let (r, g, b) = (p[0] as i32, p[1] as i32, p[2] as i32);
        if r > g + 40 && r > b + 40 {
            Some(0)
        } else if g > r + 40 && g > b + 40 {
            Some(1)
        } else if b > r + 40 && b > g + 20 {
            Some(2)
        } else if r > b + 60 && g > b + 60 {
            Some(3)
        } else {
            None
        }
    };
    let mut seen = Vec::new();
    for y in (0..h).rev() {
        let mut counts = [0usize; 4];
        for x in w / 2 - 20..w / 2 + 20 {
            if let Some(c) = cascade(f.image.get_pixel(x, y).0) {
                counts[c] += 1;
            }
        }
        let (c, n) = counts.iter().enumerate().max_by_key(|(_, n)| **n).unwrap();
        if *n >= 20 {
            seen.push(c);
        }
    }
    assert!(seen.len() > 40, "ground rows classified: {}", seen.len());
    let mut max = 0;
    for &c in &seen {
        assert!(
            c + 1 >= max,
            "cascade fell from {max} to {c} going up: {seen:?}"
        );
        max = max.max(c);
    }
    assert_eq!((seen[0], max), (0, 3), "near cascade 0, far 3: {seen:?}");
    drop(r);
    assert_validation_clean(&ctx);
}

#[test]
fn overdraw_counts_the_layers_of_three_overlapping_quads() {
    let ctx = context();
    let mut s = Scene {
        name: "layers".into(),
        ..Default::default()
    };
    for (i, x) in [-0.3f32, 0.0, 0.3].iter().enumerate() {
        add_object(
            &mut s,
            "quad",
            quad(1.0, 1.0),
            colored(Vec3::ONE, 0.5),
            Mat4::from_translation(Vec3::new(*x, 0.0, 0.1 * i as f32)),
        );
    }
    let cam = Camera::look_at(
        Vec3::new(0.0, 0.0, 3.0),
        Vec3::ZERO,
        40f32.to_radians(),
        0.01,
    );
    let f = render(&ctx, &s, &View::new(cam), ViewMode::Overdraw);
    // Each fragment adds 1/16 in linear light: decode the byte and count.
    let layers = |x: u32| -> u32 {
        let c = px(&f, x, SIZE / 2)[0] as f64 / 255.0;
        let lin = if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        };
        (lin * 16.0).round() as u32
    };
    // Image x of world x at the quads' depth (≈ 3 units away, 40° fov: 1 unit ≈ 73 px).
    let at = |wx: f32| (SIZE as f32 / 2.0 + wx * 73.0) as u32;
    assert_eq!(layers(at(0.0)), 3, "all three overlap at the centre");
    assert_eq!(layers(at(-0.5)), 2, "two at x = -0.5");
    assert_eq!(layers(at(-0.72)), 1, "one at x = -0.72");
    assert_eq!(layers(2), 0, "background");
    assert_validation_clean(&ctx);
}
