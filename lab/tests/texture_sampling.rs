//! glTF samplers and KHR_texture_transform honoured (lavapipe, validation on): magnification
//! filters, the three wrap modes per axis and texture transforms, on an unlit quad that fills the view head-on with texture coordinates from −1
//! to 2, so that every pixel's texel is known analytically: with 192 pixels over 3 units of uv and
//! 4 texels per unit, a texel is 16 pixels and no pixel centre lies on a texel boundary.

use crate::common::*;
use glam::{Mat4, Vec2, Vec3, Vec4};
use umbra::plan::{SceneOptions, View};
use umbra::render::Renderer;
use umbra::scene::built::shapes::{add_object, add_texture, quad};
use umbra::scene::{
    gltf::load_gltf, Camera, Filter, Light, Material, Sampler, Scene, Texture, TextureRef,
    UvTransform, Wrap,
};
use umbra_lab::reference::ReferenceScene;

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
    quad_scene_with(sampler, UvTransform::default())
}

fn quad_scene_with(sampler: Sampler, transform: UvTransform) -> (Scene, View) {
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
            ktx2: None,
        },
    );
    let material = Material {
        name: "unlit".into(),
        base_color: Vec4::ONE,
        base_color_texture: Some(TextureRef {
            texture: tex,
            sampler,
            transform,
            tex_coord: 0,
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
    let mut v = View::new(cam).raw_output();
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
    render_scene(ctx, quad_scene(sampler), name)
}

fn render_scene(
    ctx: &TestContext,
    (scene, view): (Scene, View),
    name: &str,
) -> (image::RgbaImage, image::RgbaImage) {
    let mut r = Renderer::new(ctx, &scene).unwrap();
    let f = r.render(&view, N, N).unwrap();
    let exact = ReferenceScene::new(&scene).render(&f.plan, N, N, f.plan.ambient);
    save(&f.image, &format!("sampler_{name}.png"));
    (f.image, exact.image)
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

/// A one-texel black-and-white checker of `size`² texels on the test quad (uv −1 to 2), under
/// the default trilinear sampler: ~3.9 texels per pixel, so the GPU samples mip levels 1–2.
fn checker_scene(size: u32) -> (Scene, View) {
    let (mut s, v) = quad_scene(Sampler::default());
    s.textures[0] = Texture {
        name: "checker".into(),
        width: size,
        height: size,
        rgba: (0..size * size)
            .flat_map(|k| {
                let c = if (k % size + k / size) % 2 == 0 {
                    0
                } else {
                    255
                };
                [c, c, c, 255]
            })
            .collect(),
        ktx2: None,
    };
    (s, v)
}

#[test]
fn minified_textures_read_mip_levels_averaged_in_linear_light() {
    let ctx = context();
    // 250 texels: not a power of two, so that without mips each pixel would land at a different
    // phase of the checker (aliasing), and levels of odd size occur (125, 62, 31...).
    let (scene, view) = checker_scene(250);
    // Both ways of making the chain: on the CPU (lavapipe's default) and by device blits (GPUs').
    for cpu_mips in [true, false] {
        let options = SceneOptions {
            cpu_mips: Some(cpu_mips),
            ..Default::default()
        };
        let mut r = Renderer::with_options(&ctx, &scene, &options).unwrap();
        let f = r.render(&view, N, N).unwrap();
        save(
            &f.image,
            &format!("sampler_minified_checker_cpu_{cpu_mips}.png"),
        );
        let grey: Vec<f64> = f.image.pixels().map(|p| p[0] as f64).collect();
        let mean = grey.iter().sum::<f64>() / grey.len() as f64;
        let spread = grey.iter().fold(0f64, |m, g| m.max((g - mean).abs()));
        eprintln!(
            "minified checker, CPU mips {cpu_mips}: mean {mean:.2}, largest deviation {spread:.1}"
        );
        // Half the light in linear terms is sRGB 187.5 (an average of the encoded bytes would
        // give 128). Measured: 188.00 from the CPU's chain, 187.00 from lavapipe's blits (the two
        // roundings of 187.5), largest deviation 0.0 for both.
        assert!((mean - 187.5).abs() <= 0.5, "CPU mips {cpu_mips}: {mean}");
        assert!(spread <= 2.0, "CPU mips {cpu_mips}: {spread}");
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
    let diff = image_diff(&soft, &soft_exact).largest();
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
fn the_loader_reads_each_textures_sampler_and_transform() {
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
    // Its textureInfo and normalTextureInfo carry KHR_texture_transform.
    let m = &scene.materials[0];
    let base = m.base_color_texture.unwrap().transform;
    assert_eq!(
        (base.offset, base.rotation, base.scale),
        (Vec2::new(0.25, 0.25), 0.3, Vec2::new(0.5, 0.5))
    );
    assert_eq!(
        m.normal_texture.unwrap().transform.offset,
        Vec2::new(0.25, 0.25)
    );
    assert_eq!(
        m.metallic_roughness_texture.unwrap().transform,
        UvTransform::default()
    );
    // Its 8×8 occlusion texture cannot be packed into the 32×32 metallic-roughness one: the one
    // warning, and the occlusion is dropped (GPU and reference alike).
    let codes: Vec<_> = scene
        .warnings
        .iter()
        .map(|w| (w.code, w.pointer.as_str()))
        .collect();
    assert_eq!(
        codes,
        [(
            "MATERIAL_OCCLUSION_IGNORED",
            "/materials/0/occlusionTexture"
        )]
    );
    assert!(m.occlusion_texture.is_none());
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

/// Offset, rotation and scale together on the base colour: every pixel whose transformed
/// coordinate lies more than 1/50 texel from a texel boundary shows the texel the extension's
/// formula gives, u' = o.x + cos θ·s.x·u + sin θ·s.y·v, v' = o.y − sin θ·s.x·u + cos θ·s.y·v.
#[test]
fn texture_transform_lands_where_the_formula_says() {
    let ctx = context();
    let t = UvTransform {
        offset: Vec2::new(0.3, -0.2),
        rotation: 30f32.to_radians(),
        scale: Vec2::new(1.5, 0.75),
    };
    let s = nearest(Wrap::Repeat, Wrap::Repeat);
    let (gpu, exact) = render_scene(&ctx, quad_scene_with(s, t), "transform");
    let (sn, cs) = t.rotation.sin_cos();
    let (mut judged, mut wrong_gpu, mut wrong_exact, mut untransformed) = (0, 0, 0, 0);
    for y in 0..N {
        for x in 0..N {
            let u = 3.0 * (x as f32 + 0.5) / N as f32 - 1.0;
            let v = 3.0 * (y as f32 + 0.5) / N as f32 - 1.0;
            let tu = t.offset.x + cs * t.scale.x * u + sn * t.scale.y * v;
            let tv = t.offset.y - sn * t.scale.x * u + cs * t.scale.y * v;
            let (fu, fv) = (tu * T as f32, tv * T as f32);
            let near_edge = |f: f32| (f - f.round()).abs() < 0.02;
            if near_edge(fu) || near_edge(fv) {
                continue;
            }
            judged += 1;
            let want = texel(
                s.wrap_u.texel(fu.floor() as i64, T as i64) as u32,
                s.wrap_v.texel(fv.floor() as i64, T as i64) as u32,
            );
            let plain = texel(
                s.wrap_u.texel((u * T as f32).floor() as i64, T as i64) as u32,
                s.wrap_v.texel((v * T as f32).floor() as i64, T as i64) as u32,
            );
            let off = |p: &image::Rgba<u8>, w: [u8; 3]| (0..3).any(|c| p[c].abs_diff(w[c]) > 1);
            wrong_gpu += off(gpu.get_pixel(x, y), want) as usize;
            wrong_exact += off(exact.get_pixel(x, y), want) as usize;
            untransformed += (!off(gpu.get_pixel(x, y), plain)) as usize;
        }
    }
    eprintln!(
        "transform: {judged} judged, GPU wrong {wrong_gpu}, reference wrong {wrong_exact}, \
         GPU pixels matching the untransformed texel {untransformed}"
    );
    assert!(judged > 30_000, "{judged}");
    // Measured: 0 and 0.
    assert_eq!((wrong_gpu, wrong_exact), (0, 0));
    // The control: without the transform most pixels would differ (chance agreement ~1/16).
    assert!(untransformed < judged / 8, "{untransformed} of {judged}");
    assert_validation_clean(&ctx);
}

/// A normal map whose left texel tilts the normal towards +x and right texel towards −x, lit by
/// a grazing sun from +x: the left half of the quad is bright, the right half dark. An offset of
/// half the map (u + 0.5) swaps them, on the GPU as in the reference.
#[test]
fn texture_transform_moves_the_normal_map_too() {
    let ctx = context();
    let halves = |offset: f32| {
        let mut s = Scene {
            name: "tilted normals".into(),
            ..Default::default()
        };
        // Tangent-space normals (±0.6, 0, 0.8) as bytes.
        let tex = add_texture(
            &mut s,
            Texture {
                name: "two tilts".into(),
                width: 2,
                height: 1,
                rgba: vec![204, 128, 230, 255, 51, 128, 230, 255],
                ktx2: None,
            },
        );
        let material = Material {
            name: "tilted".into(),
            normal_texture: Some(TextureRef {
                texture: tex,
                sampler: nearest(Wrap::Repeat, Wrap::Repeat),
                transform: UvTransform {
                    offset: Vec2::new(offset, 0.0),
                    ..Default::default()
                },
                tex_coord: 0,
            }),
            ..Default::default()
        };
        add_object(&mut s, "quad", quad(2.0, 2.0), material, Mat4::IDENTITY);
        s.lights
            .push(Light::sun(Vec3::new(-1.0, 0.0, -0.3).normalize(), 3.0));
        let cam = Camera::look_at(
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::ZERO,
            90f32.to_radians(),
            0.01,
        );
        let mut v = View::new(cam).raw_output();
        v.shadow.enabled = false;
        let (gpu, exact) = render_scene(&ctx, (s, v), &format!("normal_offset_{offset}"));
        let luma = |img: &image::RgbaImage, x0: u32, x1: u32| {
            let mut sum = 0.0;
            for y in 0..N {
                for x in x0..x1 {
                    sum += img.get_pixel(x, y)[1] as f64;
                }
            }
            sum / ((x1 - x0) * N) as f64
        };
        // Halves of the quad's u in [0, 1] (the middle third of the image), edges left out.
        let (l0, l1, r0, r1) = (68, 92, 100, 124);
        (
            (luma(&gpu, l0, l1), luma(&gpu, r0, r1)),
            (luma(&exact, l0, l1), luma(&exact, r0, r1)),
            image_diff(&gpu, &exact).largest(),
        )
    };
    let (plain, plain_exact, d0) = halves(0.0);
    let (shifted, shifted_exact, d1) = halves(0.5);
    eprintln!(
        "normal map halves (left, right) mean green: plain GPU {plain:?} ref {plain_exact:?}; \
         offset 0.5 GPU {shifted:?} ref {shifted_exact:?}; largest GPU-reference difference \
         {d0}, {d1}"
    );
    // Measured: (plain) left brighter by ~60 levels; shifted the reverse; the GPU within 2 levels
    // of the reference everywhere.
    assert!(plain.0 > plain.1 + 30.0 && plain_exact.0 > plain_exact.1 + 30.0);
    assert!(shifted.1 > shifted.0 + 30.0 && shifted_exact.1 > shifted_exact.0 + 30.0);
    assert!(d0 <= 3 && d1 <= 3, "{d0} {d1}");
    assert_validation_clean(&ctx);
}

/// The occlusion texture (red channel) scales the ambient term by 1 + strength · (occlusion − 1)
/// and nothing else: a quad lit only by ambient light (its sun behind it), occlusion 255 on the
/// left half and 64 on the right, strength 0.8: right / left in linear radiance is
/// 1 + 0.8 · (64/255 − 1) = 0.4008. With a sun in front, the GPU matches the reference, which
/// applies the formula to the ambient term alone.
#[test]
fn occlusion_scales_the_ambient_term_only() {
    let ctx = context();
    let scene_with = |sun: Vec3| {
        let mut s = Scene {
            name: "occluded".into(),
            ..Default::default()
        };
        let tex = add_texture(
            &mut s,
            Texture {
                name: "occlusion halves".into(),
                width: 2,
                height: 1,
                rgba: vec![255, 0, 0, 255, 64, 0, 0, 255],
                ktx2: None,
            },
        );
        let material = Material {
            name: "occluded".into(),
            base_color: Vec4::new(0.8, 0.8, 0.8, 1.0),
            occlusion_texture: Some(TextureRef {
                texture: tex,
                sampler: nearest(Wrap::Repeat, Wrap::Repeat),
                transform: UvTransform::default(),
                tex_coord: 0,
            }),
            occlusion_strength: 0.8,
            ..Default::default()
        };
        add_object(&mut s, "quad", quad(2.0, 2.0), material, Mat4::IDENTITY);
        s.lights.push(Light::sun(sun, 2.0));
        let cam = Camera::look_at(
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::ZERO,
            90f32.to_radians(),
            0.01,
        );
        let mut v = View::new(cam).raw_output();
        v.shadow.enabled = false;
        (s, v)
    };
    let mean_linear = |img: &image::RgbaImage, x0: u32, x1: u32| {
        let mut sum = 0.0;
        for y in 8..N - 8 {
            for x in x0..x1 {
                sum += srgb_to_linear(img.get_pixel(x, y)[1]) as f64;
            }
        }
        sum / ((x1 - x0) * (N - 16)) as f64
    };
    let (gpu, exact) = render_scene(&ctx, scene_with(Vec3::Z), "occlusion_ambient");
    let ratio = mean_linear(&gpu, N / 2 + 8, N - 8) / mean_linear(&gpu, 8, N / 2 - 8);
    let ratio_exact = mean_linear(&exact, N / 2 + 8, N - 8) / mean_linear(&exact, 8, N / 2 - 8);
    let (lit, lit_exact) = render_scene(
        &ctx,
        scene_with(Vec3::new(0.3, -0.2, -1.0).normalize()),
        "occlusion_lit",
    );
    let d = image_diff(&lit, &lit_exact).largest();
    eprintln!("occlusion: right/left {ratio:.4} (reference {ratio_exact:.4}, formula 0.4008); lit: GPU vs reference {d} levels");
    // Measured: 0.4009 on both (8-bit output quantisation).
    assert!((ratio - 0.4008).abs() < 0.005 && (ratio_exact - 0.4008).abs() < 0.005);
    assert!(d <= 2, "{d}");
    assert_validation_clean(&ctx);
}
