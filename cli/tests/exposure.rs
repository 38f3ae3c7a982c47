//! Exposure and tone mapping on content authored in physical units (lavapipe, validation on): a
//! glTF yard lit as Bevy's MixedLightingExample is (a 10⁴ lux sun and 10³ cd point lamps),
//! written here. At the defaults (auto exposure, PBR Neutral, an ambient that follows the
//! lights) under 1 % of its pixels clip at
//! 255, where the raw values (exposure 1, no curve: umbra before exposure) clip most of the
//! image; the same yard with its lights scaled to unit intensity and a matching `--exposure`
//! gives the same picture; the GPU's tone-mapped image matches the reference's.

use crate::common::gltf_builder::{Builder, Container, U16};
use crate::common::*;
use glam::{Quat, Vec3};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::Command;
use umbra::math::tonemap::ev100_from_exposure;
use umbra::plan::{Exposure, View};
use umbra::render::Renderer;
use umbra::scene::built::shapes::{cuboid, plane, uv_sphere};
use umbra::scene::{gltf::load_gltf, Primitive, Scene};
use umbra_lab::reference::ReferenceScene;

const W: u32 = 320;
const H: u32 = 240;
/// The lux scene's lights over the unit scene's.
const SCALE: f32 = 1e4;

fn mesh(b: &mut Builder, name: &str, p: &Primitive, material: usize) -> usize {
    let flat = |v: &[Vec3]| -> Vec<f32> { v.iter().flat_map(|p| p.to_array()).collect() };
    let pos = b.floats(&flat(&p.positions), 3, "VEC3");
    let nrm = b.floats(&flat(&p.normals), 3, "VEC3");
    let idx = b.indices(&p.indices, U16);
    b.mesh(
        name,
        vec![
            json!({"attributes": {"POSITION": pos, "NORMAL": nrm}, "indices": idx,
            "material": material}),
        ],
    )
}

fn pbr(rgb: [f32; 3], metallic: f32, roughness: f32) -> Value {
    json!({"pbrMetallicRoughness": {"baseColorFactor": [rgb[0], rgb[1], rgb[2], 1.0],
        "metallicFactor": metallic, "roughnessFactor": roughness}})
}

/// A 16 m yard: a grey ground, a white and a red box, a blue sphere, a gold metal ball; a sun at
/// 40° of `sun` lux and two warm lamps of `lamp` cd 1.2 m above the ground; a camera.
fn yard(dir: &Path, name: &str, sun: f32, lamp: f32) -> PathBuf {
    let mut b = Builder::default();
    let grey = b.material(pbr([0.6, 0.6, 0.6], 0.0, 0.8));
    let white = b.material(pbr([0.9, 0.9, 0.9], 0.0, 0.5));
    let red = b.material(pbr([0.8, 0.1, 0.08], 0.0, 0.4));
    let blue = b.material(pbr([0.1, 0.25, 0.8], 0.0, 0.3));
    let gold = b.material(pbr([1.0, 0.78, 0.34], 1.0, 0.25));
    let ground = mesh(&mut b, "ground", &plane(16.0, 1.0), grey);
    let cube = mesh(&mut b, "white_box", &cuboid(Vec3::splat(0.6)), white);
    let slab = mesh(&mut b, "red_box", &cuboid(Vec3::new(1.0, 0.4, 0.5)), red);
    let ball = mesh(&mut b, "blue_ball", &uv_sphere(0.7, 32, 16), blue);
    let metal = mesh(&mut b, "gold_ball", &uv_sphere(0.4, 32, 16), gold);
    for (m, t) in [
        (ground, [0.0, 0.0, 0.0]),
        (cube, [-1.5, 0.6, 0.0]),
        (slab, [1.2, 0.4, 1.2]),
        (ball, [0.6, 0.7, -1.4]),
        (metal, [-0.2, 0.4, 1.6]),
    ] {
        b.node(json!({"mesh": m, "translation": t}), true);
    }
    let ext = |l: usize| json!({"KHR_lights_punctual": {"light": l}});
    let sun_l =
        b.light(json!({"type": "directional", "intensity": sun, "color": [1.0, 0.96, 0.9]}));
    let d = Vec3::new(-0.5, -(40f32.to_radians().tan()), -0.6).normalize();
    let q = Quat::from_rotation_arc(Vec3::NEG_Z, d);
    b.node(
        json!({"rotation": q.to_array(), "extensions": ext(sun_l)}),
        true,
    );
    for p in [[-0.3, 1.2, -0.4], [2.4, 1.2, 0.2]] {
        let l = b.light(json!({"type": "point", "intensity": lamp, "color": [1.0, 0.8, 0.6]}));
        b.node(json!({"translation": p, "extensions": ext(l)}), true);
    }
    let cam = b.camera(0.9, 0.1, None);
    let look = glam::Mat4::look_at_rh(Vec3::new(4.0, 3.5, 6.5), Vec3::new(0.0, 0.4, 0.0), Vec3::Y)
        .inverse();
    let (_, r, t) = look.to_scale_rotation_translation();
    b.node(
        json!({"camera": cam, "rotation": r.to_array(), "translation": t.to_array()}),
        true,
    );
    b.write(dir, name, Container::Glb)
}

fn scenes() -> (Scene, Scene, PathBuf) {
    let dir = out_dir().join("exposure");
    let lux = yard(&dir, "yard_lux", 1e4, 1e3);
    let unit = yard(&dir, "yard_unit", 1e4 / SCALE, 1e3 / SCALE);
    (load_gltf(&lux).unwrap(), load_gltf(&unit).unwrap(), lux)
}

/// Fraction of pixels with a channel at 255.
fn clipped(img: &image::RgbaImage) -> f64 {
    let n = img.pixels().filter(|p| p.0[..3].contains(&255)).count();
    n as f64 / (img.width() * img.height()) as f64
}

/// Median of the brightest channel over the image.
fn median_level(img: &image::RgbaImage) -> u8 {
    let mut v: Vec<u8> = img
        .pixels()
        .map(|p| *p.0[..3].iter().max().unwrap())
        .collect();
    v.sort_unstable();
    v[v.len() / 2]
}

/// The yard's camera at the defaults (the ambient follows the lights: 7 % of the metered sun).
fn view(scene: &Scene) -> View {
    View::new(scene.cameras[0])
}

#[test]
fn physical_units_expose_without_clipping() {
    let ctx = context();
    let (lux, _, path) = scenes();
    let mut r = Renderer::new(&ctx, &lux).unwrap();
    let auto = r.render(&view(&lux), W, H).unwrap();
    let raw = r.render(&view(&lux).raw_output(), W, H).unwrap();
    save(&auto.image, "exposure_lux_auto.png");
    save(&raw.image, "exposure_lux_raw.png");
    let (c_auto, c_raw) = (clipped(&auto.image), clipped(&raw.image));
    let ev = ev100_from_exposure(auto.plan.exposure);
    eprintln!(
        "lux yard: auto exposure EV100 {ev:.2} (scale {:.3e}): {:.3} % clipped, median level {}; \
         raw values: {:.1} % clipped",
        auto.plan.exposure,
        100.0 * c_auto,
        median_level(&auto.image),
        100.0 * c_raw
    );
    // The bound: under 1 % clipped (measured 0.000 %); raw values clip 64.6 %.
    assert!(
        c_auto < 0.01,
        "{:.3} % clipped at the defaults",
        100.0 * c_auto
    );
    assert!(c_raw > 0.5, "raw values clip only {:.1} %", 100.0 * c_raw);
    // Not dark either: the sunlit ground and objects carry the picture.
    // Measured: median 190.
    let m = median_level(&auto.image);
    assert!((170..=215).contains(&m), "median level {m}");
    assert_validation_clean(&ctx);

    // The command line at its defaults, as a user would run it on the file.
    let png = out_dir().join("exposure_cli.png");
    let o = Command::new(env!("CARGO_BIN_EXE_umbra"))
        .args(["render", path.to_str().unwrap(), "--size", "320x240", "-o"])
        .arg(&png)
        .env("UMBRA_DEVICE", "llvmpipe")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let cli = image::open(&png).unwrap().to_rgba8();
    let c_cli = clipped(&cli);
    eprintln!(
        "umbra render at its defaults: {:.3} % clipped",
        100.0 * c_cli
    );
    assert!(c_cli < 0.01, "{:.3} % clipped by the CLI", 100.0 * c_cli);
}

#[test]
fn lux_and_unit_intensities_give_the_same_picture() {
    let ctx = context();
    let (lux, unit, _) = scenes();
    let mut rl = Renderer::new(&ctx, &lux).unwrap();
    let mut ru = Renderer::new(&ctx, &unit).unwrap();
    let a = rl.render(&view(&lux), W, H).unwrap();
    let ev = ev100_from_exposure(a.plan.exposure);
    // The unit scene with the matching exposure: log2(SCALE) stops less.
    let mut vu = view(&unit);
    vu.exposure = Exposure::Ev100(ev - SCALE.log2());
    let b = ru.render(&vu, W, H).unwrap();
    // And at its own auto exposure (metering is scale-free).
    let c = ru.render(&view(&unit), W, H).unwrap();
    assert_validation_clean(&ctx);
    save(&b.image, "exposure_unit_matched.png");
    for (name, img) in [("matching --exposure", &b.image), ("auto", &c.image)] {
        let mut worst = 0u8;
        let mut differ = 0usize;
        for (p, q) in a.image.pixels().zip(img.pixels()) {
            let d = (0..3).map(|k| p.0[k].abs_diff(q.0[k])).max().unwrap();
            worst = worst.max(d);
            differ += (d > 0) as usize;
        }
        eprintln!(
            "unit intensities, {name}: {differ} of {} pixels differ, by at most {worst} level(s)",
            W * H
        );
        // Measured: 4 (matching EV) and 5 (auto) pixels differ, by 1 level (f32 rounding).
        assert!(worst <= 1, "{name}: a pixel differs by {worst} levels");
        assert!(differ <= 30, "{name}: {differ} pixels differ");
    }
}

#[test]
fn tone_mapped_image_matches_the_reference() {
    let ctx = context();
    let (lux, _, _) = scenes();
    let mut r = Renderer::new(&ctx, &lux).unwrap();
    for tonemap in [umbra::plan::Tonemap::Neutral, umbra::plan::Tonemap::Aces] {
        let mut v = view(&lux);
        v.tonemap = tonemap;
        let f = r.render(&v, W, H).unwrap();
        let exact = ReferenceScene::new(&lux).render(&f.plan, W, H, f.plan.ambient);
        // Judged away from silhouettes and shadow edges: pixels whose 3×3 neighbourhood in the
        // reference is flat to within 6 levels.
        let e = &exact.image;
        let (mut n, mut sum, mut worst) = (0usize, 0f64, 0u8);
        for y in 1..H - 1 {
            for x in 1..W - 1 {
                let c = e.get_pixel(x, y).0;
                let flat = (-1i32..=1).all(|dy| {
                    (-1i32..=1).all(|dx| {
                        let q = e
                            .get_pixel((x as i32 + dx) as u32, (y as i32 + dy) as u32)
                            .0;
                        (0..3).all(|k| c[k].abs_diff(q[k]) <= 6)
                    })
                });
                if !flat {
                    continue;
                }
                let g = f.image.get_pixel(x, y).0;
                let d = (0..3).map(|k| c[k].abs_diff(g[k])).max().unwrap();
                n += 1;
                sum += d as f64;
                worst = worst.max(d);
            }
        }
        let mean = sum / n as f64;
        eprintln!(
            "{tonemap:?}: {n} flat pixels, mean |GPU − reference| {mean:.3} levels, worst {worst}"
        );
        assert!(n > (W * H / 2) as usize);
        // Measured: mean 0.188 (Neutral) and 0.180 (ACES) levels, worst 1.
        assert!(mean < 0.3, "{tonemap:?}: mean error {mean:.3} levels");
        assert!(worst <= 2, "{tonemap:?}: worst error {worst} levels");
    }
    assert_validation_clean(&ctx);
}
