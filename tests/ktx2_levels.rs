//! KTX2 textures (`KHR_texture_basisu`) on the device: the file's own mip levels, transcoded to
//! RGBA8 or kept block-compressed as BC7 (`SceneOptions::block_compressed`).
//!
//! What is checked independently of the code under test: the level count and sizes against the
//! KTX2 header read here; which levels the device samples, by splicing another image's levels
//! under a texture's first level (a chain made from the first level cannot show them); BC7
//! against RGBA8 by PSNR on every committed KTX2 fixture.

use crate::common::*;
use std::path::PathBuf;
use umbra::plan::{SceneOptions, View};
use umbra::render::Renderer;
use umbra::scene::gltf::compressed::{ktx2_levels, Ktx2Target};
use umbra::scene::{gltf::load_gltf, Scene};

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/compressed")
        .join(name)
}

fn word(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
}

fn dword(b: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(b[at..at + 8].try_into().unwrap())
}

/// (width, height, level count) from a KTX2 header.
fn header(k: &[u8]) -> (u32, u32, u32) {
    assert_eq!(&k[..12], b"\xABKTX 20\xBB\r\n\x1A\n", "not a KTX2 file");
    (word(k, 20), word(k, 24), word(k, 40).max(1))
}

/// `a` with its levels from 1 on replaced by `b`'s (both Zstd-supercompressed UASTC of one size:
/// each level stands alone): `b`'s level data appended, `a`'s level index pointed at it.
fn splice(a: &[u8], b: &[u8]) -> Vec<u8> {
    assert_eq!(header(a), header(b));
    assert_eq!(
        (word(a, 44), word(b, 44)),
        (2, 2),
        "both Zstd-supercompressed"
    );
    let mut out = a.to_vec();
    for level in 1..header(a).2 as usize {
        let at = 80 + level * 24;
        let (off, len) = (dword(b, at) as usize, dword(b, at + 8) as usize);
        let new_off = out.len() as u64;
        out.extend_from_slice(&b[off..off + len]);
        out[at..at + 8].copy_from_slice(&new_off.to_le_bytes());
        out[at + 8..at + 24].copy_from_slice(&b[at + 8..at + 24]);
    }
    out
}

#[test]
fn ktx2_levels_are_the_files_own() {
    for name in ["normal_mapped.uastc.glb", "normal_mapped.etc1s.glb"] {
        let scene = load_gltf(&fixture(name)).unwrap();
        let mut checked = 0;
        for t in &scene.textures {
            let k = t
                .ktx2
                .as_deref()
                .expect("every image of the fixture is KTX2");
            let (w, h, count) = header(k);
            assert_eq!((t.width, t.height), (w, h), "{name}: {}", t.name);
            assert!(count > 1, "{name}: the encoder wrote mips (-mipmap)");
            for target in [Ktx2Target::Rgba8, Ktx2Target::Bc7] {
                let c = ktx2_levels(k, target).unwrap();
                assert_eq!(c.levels.len() as u32, count, "{name} {target:?}");
                let mut at = 0;
                for (l, &(lw, lh, off)) in c.levels.iter().enumerate() {
                    assert_eq!((lw, lh), ((w >> l).max(1), (h >> l).max(1)));
                    assert_eq!(off, at);
                    at += match target {
                        Ktx2Target::Rgba8 => (lw * lh * 4) as usize,
                        Ktx2Target::Bc7 => (lw.div_ceil(4) * lh.div_ceil(4) * 16) as usize,
                    };
                }
                assert_eq!(c.bytes.len(), at);
                if target == Ktx2Target::Rgba8 {
                    assert_eq!(
                        &c.bytes[..t.rgba.len()],
                        &t.rgba[..],
                        "level 0 is the image"
                    );
                }
            }
            checked += 1;
        }
        assert_eq!(checked, 5, "{name}");
    }
}

/// `scene` rendered at `w`×`h` from its default camera with `options`, and the texture figures.
fn shot(
    ctx: &std::sync::Arc<umbra::gpu::Context>,
    scene: &Scene,
    options: &SceneOptions,
    (w, h): (u32, u32),
) -> (image::RgbaImage, umbra::render::TextureStats) {
    let mut r = Renderer::with_options(ctx, scene, options).unwrap();
    let view = View::new(scene.default_camera(w as f32 / h as f32));
    (r.render(&view, w, h).unwrap().image, r.texture_stats())
}

#[test]
fn the_device_samples_the_files_levels() {
    // The base colour's first level kept, its other levels taken from the normal map: where the
    // base colour is minified, the image must change; where it is magnified, hardly at all.
    let mut spliced = load_gltf(&fixture("normal_mapped.uastc.glb")).unwrap();
    let m = &spliced.materials[0];
    let (base, normal) = (
        m.base_color_texture.unwrap().texture,
        m.normal_texture.unwrap().texture,
    );
    let original = spliced.clone();
    let t = &spliced.textures;
    let k = splice(
        t[base].ktx2.as_deref().unwrap(),
        t[normal].ktx2.as_deref().unwrap(),
    );
    assert_eq!(
        &ktx2_levels(&k, Ktx2Target::Rgba8).unwrap().bytes[..t[base].rgba.len()],
        &t[base].rgba[..]
    );
    spliced.textures[base].ktx2 = Some(k.into());
    let ctx = context();
    for bc7 in [false, true] {
        let options = SceneOptions {
            block_compressed: Some(bc7),
            ..Default::default()
        };
        let mut rows = Vec::new();
        for size in [(40, 30), (640, 480)] {
            let (a, sa) = shot(&ctx, &original, &options, size);
            let (b, sb) = shot(&ctx, &spliced, &options, size);
            assert_eq!(sa, sb);
            assert_eq!(
                (sa.file_mips, sa.bc7),
                (4, if bc7 { 4 } else { 0 }),
                "{sa:?}"
            );
            let d = image_diff(&a, &b);
            let n = (size.0 * size.1) as f64;
            save(&b, &format!("ktx2_spliced_{}_bc7_{bc7}.png", size.0));
            rows.push((d.over(8) as f64 / n, d.psnr()));
        }
        eprintln!("spliced levels, BC7 {bc7}: minified, magnified (share of pixels over 8 levels, PSNR): {rows:?}");
        let [(far, far_psnr), (near, _)] = rows[..] else {
            unreachable!()
        };
        // Measured: minified 12.2 % of pixels over 8 levels (21.4 dB), magnified 1.4 % (where
        // the cube and sphere turn away); the same levels would give 0 and 0.
        assert!(far >= 0.06 && far_psnr < 30.0, "minified: {far} {far_psnr}");
        assert!(near <= 0.03, "magnified: {near}");
    }
    assert_validation_clean(&ctx);
}

#[test]
fn bc7_renders_like_rgba8_on_every_ktx2_fixture() {
    let mut names: Vec<PathBuf> = std::fs::read_dir(fixture(""))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let n = p.to_string_lossy();
            n.ends_with(".uastc.glb") || n.ends_with(".etc1s.glb")
        })
        .collect();
    names.sort();
    assert!(names.len() >= 8, "{names:?}");
    let ctx = context();
    let (mut rows, mut psnrs) = (Vec::new(), Vec::new());
    for p in &names {
        let scene = load_gltf(p).unwrap();
        let opts = |bc7| SceneOptions {
            block_compressed: Some(bc7),
            ..Default::default()
        };
        let (a, sa) = shot(&ctx, &scene, &opts(false), (320, 240));
        let (b, sb) = shot(&ctx, &scene, &opts(true), (320, 240));
        let name = p.file_name().unwrap().to_string_lossy().to_string();
        let psnr = image_diff(&a, &b).psnr();
        rows.push(format!(
            "{name}: {psnr:.1} dB, {} of {} images BC7, {} -> {} bytes",
            sb.bc7, sb.images, sa.bytes, sb.bytes
        ));
        assert!(sa.file_mips > 0 && sa.bc7 == 0, "{name}: {sa:?}");
        assert_eq!(
            (sb.file_mips, sb.bc7),
            (sa.file_mips, sa.file_mips),
            "{name}"
        );
        assert!(sb.bytes * 3 < sa.bytes, "{name}: {sb:?} against {sa:?}");
        psnrs.push((name, psnr));
    }
    eprintln!("{}", rows.join("\n"));
    // Measured least: ETC1S 38.2 dB (indexed_boxes; the transcoder's ETC1S→BC7 is lossy), UASTC
    // 61.9 dB (normal_mapped).
    for (name, psnr) in psnrs {
        let least = if name.contains("etc1s") { 36.0 } else { 58.0 };
        assert!(psnr >= least, "{name}: {psnr:.1} dB < {least}");
    }
    assert_validation_clean(&ctx);
}
