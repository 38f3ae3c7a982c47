//! Multisample anti-aliasing (lavapipe, validation on): boxes, a sphere and a thin post on a
//! ground under a low sun, rendered at 1, 2, 4 and 8 samples (those the device has) and judged
//! against a 16× supersampled render of the same view (4× the width and height at one sample,
//! averaged over 4×4 blocks in linear light) on the pixels that hold an edge: the error falls
//! with the sample count, and pixels away from edges do not change (MSAA touches only edges, so
//! no shadow leaks along them).

use crate::common::*;
use glam::{Mat4, Vec3};
use umbra::plan::{FramePlan, ScenePlanner};
use umbra::plan::{PostAa, SceneOptions, View};
use umbra::render::Renderer;
use umbra::scene::built::shapes::{add_object, colored, cuboid, plane, uv_sphere};
use umbra::scene::{Camera, Light, Scene};

const W: u32 = 240;
const H: u32 = 180;
const SS: u32 = 4;

fn scene() -> Scene {
    let mut s = Scene {
        name: "msaa".into(),
        ..Default::default()
    };
    add_object(
        &mut s,
        "ground",
        plane(12.0, 1.0),
        colored(Vec3::splat(0.7), 0.9),
        Mat4::IDENTITY,
    );
    for (i, (half, at, rgb)) in [
        (
            Vec3::new(0.6, 0.6, 0.6),
            Vec3::new(-1.2, 0.6, 0.0),
            Vec3::new(0.8, 0.15, 0.1),
        ),
        (
            Vec3::new(0.05, 1.2, 0.05),
            Vec3::new(1.0, 1.2, -0.8),
            Vec3::splat(0.9),
        ),
        (
            Vec3::new(1.0, 0.25, 0.3),
            Vec3::new(0.6, 0.25, 1.2),
            Vec3::new(0.1, 0.3, 0.8),
        ),
    ]
    .into_iter()
    .enumerate()
    {
        add_object(
            &mut s,
            &format!("box{i}"),
            cuboid(half),
            colored(rgb, 0.5),
            Mat4::from_translation(at),
        );
    }
    add_object(
        &mut s,
        "ball",
        uv_sphere(0.5, 48, 24),
        colored(Vec3::new(0.9, 0.8, 0.2), 0.4),
        Mat4::from_translation(Vec3::new(0.2, 0.5, -1.4)),
    );
    s.lights
        .push(Light::sun(Vec3::new(-0.6, -0.45, -0.5).normalize(), 3.0));
    s
}

fn view() -> View {
    let mut v = View::new(Camera::look_at(
        Vec3::new(3.5, 2.6, 4.5),
        Vec3::new(0.0, 0.4, 0.0),
        50f32.to_radians(),
        0.1,
    ));
    // The same shadow map at every image size (the automatic cascade count follows pixels).
    v.shadow.cascades = 1;
    v
}

fn linear(img: &image::RgbaImage, x: u32, y: u32) -> [f32; 3] {
    let p = img.get_pixel(x, y).0;
    [0, 1, 2].map(|k| srgb_to_linear(p[k]))
}

/// A renderer of `s` at `samples` samples a pixel.
fn renderer(ctx: &std::sync::Arc<umbra::gpu::Context>, s: &Scene, samples: u32) -> Renderer {
    Renderer::with_options(
        ctx,
        s,
        &SceneOptions {
            msaa: Some(samples),
            ..Default::default()
        },
    )
    .unwrap()
}

/// The 16× supersampled truth of `s` seen by `v` (box-filtered in linear light, in sRGB
/// levels), which pixels hold an edge (their 4×4 block spans more than 16 levels in some
/// channel) and which are flat (no channel spans more than 4).
struct Truth {
    levels: Vec<[f32; 3]>,
    edge: Vec<bool>,
    flat: Vec<bool>,
}

fn supersampled(ctx: &std::sync::Arc<umbra::gpu::Context>, s: &Scene, v: &View) -> Truth {
    let big = renderer(ctx, s, 1).render(v, W * SS, H * SS).unwrap().image;
    // The supersampled image, box-filtered in linear light, and which pixels hold an edge (their
    // 4×4 block spans more than 16 levels in some channel).
    let mut truth = vec![[0f32; 3]; (W * H) as usize];
    let mut edge = vec![false; (W * H) as usize];
    let mut flat = vec![false; (W * H) as usize];
    for y in 0..H {
        for x in 0..W {
            let (mut lo, mut hi) = ([255u8; 3], [0u8; 3]);
            let mut sum = [0f32; 3];
            for j in 0..SS {
                for i in 0..SS {
                    let (bx, by) = (x * SS + i, y * SS + j);
                    let p = big.get_pixel(bx, by).0;
                    let l = linear(&big, bx, by);
                    for k in 0..3 {
                        lo[k] = lo[k].min(p[k]);
                        hi[k] = hi[k].max(p[k]);
                        sum[k] += l[k];
                    }
                }
            }
            let n = (SS * SS) as f32;
            truth[(y * W + x) as usize] = sum.map(|c| linear_to_srgb(c / n));
            edge[(y * W + x) as usize] = (0..3).any(|k| hi[k] - lo[k] > 16);
            flat[(y * W + x) as usize] = (0..3).all(|k| hi[k] - lo[k] <= 4);
        }
    }
    Truth {
        levels: truth,
        edge,
        flat,
    }
}

/// The mean of the largest channel error against `t` over its edge pixels, the worst, and how
/// many of its flat pixels differ from `reference` by more than 2 levels.
fn edge_error(
    img: &image::RgbaImage,
    t: &Truth,
    reference: Option<&image::RgbaImage>,
) -> (f64, f32, usize) {
    let (mut sum, mut worst, mut off_edge) = (0f64, 0f32, 0usize);
    for y in 0..H {
        for x in 0..W {
            let i = (y * W + x) as usize;
            let p = img.get_pixel(x, y).0;
            let d = (0..3)
                .map(|k| (p[k] as f32 - t.levels[i][k]).abs())
                .fold(0.0, f32::max);
            if t.edge[i] {
                sum += d as f64;
                worst = worst.max(d);
            } else if let Some(one) = reference.filter(|_| t.flat[i]) {
                let q = one.get_pixel(x, y).0;
                off_edge += (0..3).any(|k| p[k].abs_diff(q[k]) > 2) as usize;
            }
        }
    }
    let edges = t.edge.iter().filter(|&&e| e).count();
    (sum / edges as f64, worst, off_edge)
}

#[test]
fn msaa_error_on_edges_falls_with_sample_count() {
    let ctx = context();
    let s = scene();
    let v = view();
    let t = supersampled(&ctx, &s, &v);
    let edges = t.edge.iter().filter(|&&e| e).count();
    let flats = t.flat.iter().filter(|&&f| f).count();
    let mut results = Vec::new();
    let mut one_sample: Option<image::RgbaImage> = None;
    for n in [1u32, 2, 4, 8] {
        let mut r = renderer(&ctx, &s, n);
        if r.samples() != n {
            eprintln!(
                "{n} samples: not on this device (it would use {})",
                r.samples()
            );
            continue;
        }
        let img = r.render(&v, W, H).unwrap().image;
        save(&img, &format!("msaa_{n}x.png"));
        // Away from edges MSAA shades as one sample does (within rounding: on a face's inner
        // diagonal each triangle shades its samples at its own centroid, which moves the
        // specular term by a level or two).
        let (mean, worst, off_edge) = edge_error(&img, &t, one_sample.as_ref());
        eprintln!(
            "{n} sample(s): edge pixels {edges}, mean error against 16× supersampling \
             {mean:.2} levels (worst {worst:.0}); {off_edge} of {flats} flat pixels differ from 1 \
             sample by more than 2 levels"
        );
        if n == 1 {
            one_sample = Some(img);
        }
        results.push((n, mean, off_edge));
    }
    assert_validation_clean(&ctx);
    assert!(edges > 800, "{edges} edge pixels");
    assert!(
        results.len() >= 2 && results[0].0 == 1,
        "needs 1 and another sample count: {results:?}"
    );
    for w in results.windows(2) {
        assert!(w[1].1 < w[0].1, "error does not fall: {results:?}");
    }
    let (_, e1, _) = results[0];
    let (n, en, _) = *results.last().unwrap();
    // Measured on lavapipe (1 and 4 samples): 29.97 and 9.56 levels (0.32×); 0 flat pixels
    // changed by more than 2 levels (3, on a box face's inner diagonal, by 2).
    assert!(
        en < 0.4 * e1,
        "{n} samples: {en:.2} levels against {e1:.2} at 1"
    );
    for &(n, _, off) in &results[1..] {
        assert!(off == 0, "{n} samples changed {off} flat pixels");
    }
}

/// The scene, its view and 16× truth, a one-sample renderer and its image.
fn one_sample() -> (TestContext, Scene, View, Truth, Renderer, image::RgbaImage) {
    let ctx = context();
    let s = scene();
    let v = view();
    let t = supersampled(&ctx, &s, &v);
    let mut r = renderer(&ctx, &s, 1);
    let plain = r.render(&v, W, H).unwrap().image;
    (ctx, s, v, t, r, plain)
}

/// FXAA (`View::post_aa`) over the one-sample image: the edge error against the same 16×
/// supersampled truth falls, flat pixels stay as drawn, and the pass is validation-clean.
#[test]
fn fxaa_lowers_the_edge_error_and_keeps_flat_pixels() {
    let (ctx, _, mut v, t, mut r, plain) = one_sample();
    v.post_aa = PostAa::Fxaa;
    let smooth = r.render(&v, W, H).unwrap().image;
    save(&smooth, "msaa_fxaa.png");
    let (e1, _, _) = edge_error(&plain, &t, None);
    let (ef, worst, off) = edge_error(&smooth, &t, Some(&plain));
    let identical = (0..H)
        .flat_map(|y| (0..W).map(move |x| (x, y)))
        .filter(|&(x, y)| t.flat[(y * W + x) as usize])
        .filter(|&(x, y)| plain.get_pixel(x, y) == smooth.get_pixel(x, y))
        .count();
    let flats = t.flat.iter().filter(|&&f| f).count();
    eprintln!(
        "FXAA: mean edge error {ef:.2} levels (worst {worst:.0}) against {e1:.2} without; \
         {identical} of {flats} flat pixels unchanged to the bit, {off} changed by more than 2 \
         levels"
    );
    assert_validation_clean(&ctx);
    // Measured on lavapipe: 12.20 levels against 29.97 (0.41×; 4 samples: 9.56); 41,165 of
    // 41,968 flat pixels unchanged to the bit (98.1 %), 655 (1.56 %) moved by more than 2
    // levels: pixels beside an edge, which FXAA blends across it as it does the edge's own.
    assert!(
        ef < 0.45 * e1,
        "FXAA: {ef:.2} levels against {e1:.2} without"
    );
    assert!(
        identical * 100 > 97 * flats,
        "FXAA kept {identical} of {flats} flat pixels"
    );
    assert!(
        off * 50 < flats,
        "FXAA changed {off} of {flats} flat pixels"
    );
}

/// Supersampling (`View::supersample` 2): each pixel is the mean, in linear light, of the 2×2
/// pixels of the same view drawn at twice the size (computed here from that render, not by the
/// blit under test), its edge error against the 16× truth falls to 4× MSAA's level, the shadow
/// maps are planned for the image's pixels, and a factor the renderer lacks is an error, not a
/// panic.
#[test]
fn supersampling_is_the_mean_of_a_render_at_twice_the_size() {
    let (ctx, s, mut v, t, mut r, plain) = one_sample();
    let big = r.render(&v, 2 * W, 2 * H).unwrap().image;
    v.supersample = 2;
    let frame = r.render(&v, W, H).unwrap();
    let img = frame.image;
    save(&img, "msaa_ssaa2.png");
    assert_eq!((img.width(), img.height()), (W, H));
    // With the cascades fitted to the depths a frame sees, the supersampled image is the one a
    // renderer that drew nothing before gives (the depths are measured per drawn size, not
    // reused from the one-sample frame of the same camera).
    let mut fit = v.clone();
    fit.shadow.depth_fit = true;
    fit.shadow.cascades = 2;
    fit.supersample = 1;
    r.render(&fit, W, H).unwrap();
    fit.supersample = 2;
    let after = r.render(&fit, W, H).unwrap().image;
    let fresh = renderer(&ctx, &s, 1).render(&fit, W, H).unwrap().image;
    assert!(
        fresh == after,
        "the supersampled image depends on the frames drawn before"
    );
    let mut worst_mean = 0u8;
    for y in 0..H {
        for x in 0..W {
            let mut sum = [0f32; 3];
            for (i, j) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let l = linear(&big, 2 * x + i, 2 * y + j);
                for k in 0..3 {
                    sum[k] += l[k];
                }
            }
            let p = img.get_pixel(x, y).0;
            for k in 0..3 {
                let want = linear_to_srgb(sum[k] / 4.0).round() as u8;
                worst_mean = worst_mean.max(p[k].abs_diff(want));
            }
        }
    }
    let (e1, _, _) = edge_error(&plain, &t, None);
    let (es, worst, off) = edge_error(&img, &t, Some(&plain));
    let flats = t.flat.iter().filter(|&&f| f).count();
    eprintln!(
        "2×2 supersampling: at most {worst_mean} level(s) from the mean of the render at twice \
         the size; mean edge error {es:.2} levels (worst {worst:.0}) against {e1:.2} at one \
         sample; {off} of {flats} flat pixels differ from one sample by more than 2 levels"
    );
    // The shadow maps are planned for the image's pixels: with the automatic cascade count and
    // a 256² map, one map here, where a frame drawn at twice the size gets two cascades.
    v.shadow.cascades = 0;
    v.shadow.map_size = 256;
    let sides = |p: &FramePlan| p.shadow_views.iter().map(|x| x.res).collect::<Vec<_>>();
    let planner = ScenePlanner::new(&s);
    assert_eq!(sides(&planner.plan(&v, 2 * W, 2 * H)), [256, 256]);
    assert_eq!(sides(&r.render(&v, W, H).unwrap().plan), [256]);
    v.supersample = 3;
    let err = r.render(&v, W, H).err().map(|e| e.to_string());
    assert!(
        err.as_deref().is_some_and(|e| e.contains("supersample 3")),
        "{err:?}"
    );
    assert_validation_clean(&ctx);
    // Measured on lavapipe: at most 1 level from the mean (rounding); 9.78 levels against
    // 30.00 at one sample (0.326×; 4× MSAA 9.56, FXAA 12.21); no flat pixel moved by more
    // than 2 levels.
    assert!(worst_mean <= 1, "{worst_mean} levels from the 2×2 mean");
    assert!(es < 0.35 * e1, "2×2: {es:.2} levels against {e1:.2} at 1");
    assert!(off == 0, "2×2 changed {off} flat pixels");
}
