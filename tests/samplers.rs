//! glTF samplers honoured (lavapipe, validation on): magnification filters and the three wrap
//! modes per axis, on an unlit quad that fills the view head-on with texture coordinates from −1
//! to 2, so that every pixel's texel is known analytically: with 192 pixels over 3 units of uv and
//! 4 texels per unit, a texel is 16 pixels and no pixel centre lies on a texel boundary.

mod common;

use common::*;
use glam::{Mat4, Vec2, Vec3, Vec4};
use umbra::reference::ReferenceScene;
use umbra::render::{Renderer, View};
use umbra::scene::shapes::{add_object, add_texture, quad};
use umbra::scene::{
    load_gltf, Camera, Filter, Material, Sampler, Scene, Texture, TextureRef, Wrap,
};

const N: u32 = 192;
/// Texels per side of the test texture.
const T: u32 = 4;

/// sRGB bytes of texel (i, j): sixteen distinct colours.
fn texel(i: u32, j: u32) -> [u8; 3] {
    [(i * 60 + 20) as u8, (j * 60 + 20) as u8, 128]
}

/// A 2 × 2 unlit quad at z = 0 with uv from −1 to 2, sampled with `sampler`, and a 90° camera at
/// z = 1 that sees exactly the quad.
fn quad_scene(sampler: Sampler) -> (Scene, View) {
    let mut s = Scene {
        name: "sampler quad".into(),
        ..Default::default()
    };
    let tex = add_texture(
        &mut s,
        Texture {
            name: "16 colours".into(),
            width: T,
            height: T,
            rgba: (0..T * T)
                .flat_map(|k| {
                    let [r, g, b] = texel(k % T, k / T);
                    [r, g, b, 255]
                })
                .collect(),
        },
    );
    let material = Material {
        name: "unlit".into(),
        base_color: Vec4::ONE,
        base_color_texture: Some(TextureRef {
            texture: tex,
            sampler,
        }),
        unlit: true,
        ..Default::default()
    };
    let mut q = quad(2.0, 2.0);
    for uv in &mut q.uvs {
        *uv = *uv * 3.0 - Vec2::ONE;
    }
    add_object(&mut s, "quad", q, material, Mat4::IDENTITY);
    let cam = Camera::look_at(
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::ZERO,
        90f32.to_radians(),
        0.01,
    );
    let mut v = View::new(cam);
    v.shadow.enabled = false;
    (s, v)
}

/// Pixels (of N²) whose colour is not texel (wrap_u(⌊4u⌋), wrap_v(⌊4v⌋)) within one level.
fn nearest_mismatches(img: &image::RgbaImage, s: &Sampler) -> usize {
    let mut wrong = 0;
    for y in 0..N {
        for x in 0..N {
            let u = 3.0 * (x as f32 + 0.5) / N as f32 - 1.0;
            let v = 3.0 * (y as f32 + 0.5) / N as f32 - 1.0;
            let i = s.wrap_u.texel((u * T as f32).floor() as i64, T as i64) as u32;
            let j = s.wrap_v.texel((v * T as f32).floor() as i64, T as i64) as u32;
            let want = texel(i, j);
            let p = img.get_pixel(x, y);
            if (0..3).any(|c| p[c].abs_diff(want[c]) > 1) {
                wrong += 1;
            }
        }
    }
    wrong
}

fn render(ctx: &TestContext, sampler: Sampler, name: &str) -> (image::RgbaImage, image::RgbaImage) {
    let (scene, view) = quad_scene(sampler);
    let mut r = Renderer::new(ctx, &scene).unwrap();
    let f = r.render(&view, N, N).unwrap();
    let exact = ReferenceScene::new(&scene).render(&f.plan, N, N, view.ambient);
    save(&f.image, &format!("sampler_{name}.png"));
    (f.image, exact.image)
}

fn largest_difference(a: &image::RgbaImage, b: &image::RgbaImage) -> u8 {
    a.pixels()
        .zip(b.pixels())
        .flat_map(|(p, q)| (0..3).map(move |c| p[c].abs_diff(q[c])))
        .max()
        .unwrap_or(0)
}

fn nearest(wrap_u: Wrap, wrap_v: Wrap) -> Sampler {
    Sampler {
        mag: Filter::Nearest,
        min: Filter::Nearest,
        mipmap: None,
        wrap_u,
        wrap_v,
    }
}

#[test]
fn wrap_modes_per_axis_land_where_the_formula_says() {
    let ctx = context();
    for (u, v) in [
        (Wrap::Repeat, Wrap::Repeat),
        (Wrap::MirroredRepeat, Wrap::ClampToEdge),
        (Wrap::ClampToEdge, Wrap::MirroredRepeat),
    ] {
        let s = nearest(u, v);
        let (gpu, exact) = render(&ctx, s, &format!("{u:?}_{v:?}"));
        // Measured: 0 of 36,864 on the GPU and in the reference.
        assert_eq!(nearest_mismatches(&gpu, &s), 0, "GPU, {u:?} × {v:?}");
        assert_eq!(
            nearest_mismatches(&exact, &s),
            0,
            "reference, {u:?} × {v:?}"
        );
        // The control: the same image under the default sampler's wraps is far off.
        let other = nearest(Wrap::Repeat, Wrap::Repeat);
        if s != other {
            assert!(nearest_mismatches(&gpu, &other) > 5000, "{u:?} × {v:?}");
        }
    }
    assert_validation_clean(&ctx);
}

#[test]
fn nearest_magnification_keeps_hard_texel_edges_and_linear_blends_them() {
    let ctx = context();
    let colours = |img: &image::RgbaImage| {
        img.pixels()
            .map(|p| [p[0], p[1], p[2]])
            .collect::<std::collections::HashSet<_>>()
            .len()
    };
    let (hard, _) = render(&ctx, nearest(Wrap::Repeat, Wrap::Repeat), "nearest");
    let linear = Sampler {
        mipmap: None,
        ..Sampler::default()
    };
    let (soft, soft_exact) = render(&ctx, linear, "linear");
    let (hard_n, soft_n) = (colours(&hard), colours(&soft));
    let diff = largest_difference(&soft, &soft_exact);
    eprintln!("colours: nearest {hard_n}, linear {soft_n}; linear GPU vs reference: {diff} levels");
    // Nearest: the 16 texel colours and nothing between them.
    assert_eq!(hard_n, 16);
    // Linear: ramps between texels (measured 1,500+ colours), matching the reference's bilinear
    // sample within a few levels (measured: 2).
    assert!(soft_n > 1000, "{soft_n}");
    assert!(diff <= 3, "{diff}");
    assert_validation_clean(&ctx);
}

#[test]
fn the_loader_reads_each_textures_sampler() {
    let files = corpus::write_corpus(&out_dir().join("corpus_samplers"));
    let boxes = files
        .iter()
        .find(|p| p.to_string_lossy().contains("indexed_boxes"))
        .unwrap();
    let scene = load_gltf(boxes).unwrap();
    let t = scene.materials[0].base_color_texture.unwrap();
    // The corpus writes mag LINEAR, min LINEAR_MIPMAP_LINEAR, wrap S REPEAT, T MIRRORED_REPEAT.
    assert_eq!(
        t.sampler,
        Sampler {
            mag: Filter::Linear,
            min: Filter::Linear,
            mipmap: Some(Filter::Linear),
            wrap_u: Wrap::Repeat,
            wrap_v: Wrap::MirroredRepeat,
        }
    );
    let normal = files
        .iter()
        .find(|p| p.to_string_lossy().contains("normal_mapped"))
        .unwrap();
    let scene = load_gltf(normal).unwrap();
    let s = scene
        .materials
        .iter()
        .find_map(|m| m.base_color_texture.or(m.normal_texture))
        .unwrap()
        .sampler;
    // mag LINEAR, min NEAREST_MIPMAP_LINEAR, both axes CLAMP_TO_EDGE.
    assert_eq!(
        (s.min, s.mipmap, s.wrap_u, s.wrap_v),
        (
            Filter::Nearest,
            Some(Filter::Linear),
            Wrap::ClampToEdge,
            Wrap::ClampToEdge
        )
    );
}
