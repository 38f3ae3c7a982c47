use super::*;
use crate::scene::built::foliage::{leaf_texture, LEAF_TEXTURE_SIZE};
use crate::scene::built::shapes::{plane, quad};
use crate::scene::{TextureRef, Wrap};

fn leaf_material(mode: AlphaMode) -> Material {
    Material {
        base_color_texture: Some(TextureRef::new(0)),
        alpha_mode: mode,
        double_sided: true,
        ..Default::default()
    }
}

/// Bilinear alpha at `uv` as the device's sampler reads mip 0 (texel centres at +0.5, the
/// sampler's wrap), written here apart from the code under test.
fn bilinear_alpha(t: &Texture, wrap: (Wrap, Wrap), uv: Vec2) -> f32 {
    let (w, h) = (t.width as i64, t.height as i64);
    let x = uv.x * w as f32 - 0.5;
    let y = uv.y * h as f32 - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let a = |i: i64, j: i64| {
        let (i, j) = (wrap.0.texel(i, w), wrap.1.texel(j, h));
        t.rgba[((j * w + i) * 4 + 3) as usize] as f32 / 255.0
    };
    let (i, j) = (x0 as i64, y0 as i64);
    let top = a(i, j) * (1.0 - fx) + a(i + 1, j) * fx;
    let bottom = a(i, j + 1) * (1.0 - fx) + a(i + 1, j + 1) * fx;
    top * (1.0 - fy) + bottom * fy
}

/// Whether `uv` lies in a triangle of `p` (in texture space).
fn covered(p: &Primitive, uv: Vec2) -> bool {
    p.indices.chunks_exact(3).any(|t| {
        let [a, b, c] = [0, 1, 2].map(|k| p.uvs[t[k] as usize]);
        let s = (b - a).perp_dot(c - a).signum();
        [(a, b), (b, c), (c, a)]
            .iter()
            .all(|(p0, p1)| (*p1 - *p0).perp_dot(uv - *p0) * s >= -1e-6)
    })
}

/// A deterministic point sequence filling the unit square (R2 low-discrepancy).
fn samples(n: usize) -> impl Iterator<Item = Vec2> {
    (0..n).map(|k| {
        let k = k as f32 + 0.5;
        Vec2::new((k * 0.754_877_7).fract(), (k * 0.569_840_3).fract())
    })
}

#[test]
fn a_leaf_card_keeps_every_point_that_can_pass() {
    let textures = [leaf_texture(LEAF_TEXTURE_SIZE)];
    // With the default repeating sampler the stem at the card's bottom edge reaches its top
    // edge too (bilinear filtering wraps), so the cut polygon must hold both ends.
    for (mode, cutoff, wrap, kept) in [
        (AlphaMode::Blend, 0.5, Wrap::Repeat, 0.65..0.71),
        (AlphaMode::Mask(0.3), 0.3, Wrap::Repeat, 0.65..0.71),
        (AlphaMode::Blend, 0.5, Wrap::ClampToEdge, 0.34..0.40),
    ] {
        let card = quad(0.7, 0.7);
        let mut m = leaf_material(mode);
        if let Some(t) = &mut m.base_color_texture {
            t.sampler.wrap_u = wrap;
            t.sampler.wrap_v = wrap;
        }
        let cut = AlphaCut::new(&m, &card, &textures).expect("a cutout material");
        let t = trim(&card, &cut).expect("the card is cut");
        assert_eq!((t.cut, t.dropped), (1, 0));
        // Measured: 0.680 of the card kept repeating (at 0.5 and at 0.3), 0.369 clamped
        // (its bounding rectangle; the texels that can pass are 0.17-0.19 of it).
        assert!(kept.contains(&t.kept_area), "{} kept", t.kept_area);
        let mut passing = 0;
        for uv in samples(200_000) {
            if bilinear_alpha(&textures[0], (wrap, wrap), uv) >= cutoff {
                passing += 1;
                assert!(covered(&t.primitive, uv), "{uv} passes but was cut away");
            }
        }
        assert!(passing > 20_000, "{passing} samples pass");
        // New vertices lie on the card, where their coordinates put them.
        for i in card.positions.len()..t.primitive.positions.len() {
            let (p, uv) = (t.primitive.positions[i], t.primitive.uvs[i]);
            let expect = Vec3::new((uv.x - 0.5) * 0.7, (0.5 - uv.y) * 0.7, 0.0);
            assert!((p - expect).length() < 1e-6, "{p} for {uv}");
        }
    }
}

#[test]
fn a_clear_card_is_left_out_and_an_opaque_one_kept_whole() {
    let mut clear = leaf_texture(16);
    clear.rgba.chunks_mut(4).for_each(|p| p[3] = 0);
    let card = quad(1.0, 1.0);
    let m = leaf_material(AlphaMode::Mask(0.5));
    let t = trim(&card, &AlphaCut::new(&m, &card, &[clear]).unwrap()).unwrap();
    assert_eq!((t.cut, t.dropped, t.primitive.indices.len()), (0, 1, 0));
    let mut opaque = leaf_texture(16);
    opaque.rgba.chunks_mut(4).for_each(|p| p[3] = 255);
    assert!(trim(&card, &AlphaCut::new(&m, &card, &[opaque]).unwrap()).is_none());
    // An opaque material has no alpha test to cut to.
    let textures = [leaf_texture(16)];
    assert!(AlphaCut::new(&leaf_material(AlphaMode::Opaque), &card, &textures).is_none());
}

#[test]
fn triangles_sharing_edges_with_the_rest_of_the_mesh_are_kept() {
    // Two quads side by side share an edge: no lone patch, nothing cut.
    let mut strip = quad(1.0, 1.0);
    let right = quad(1.0, 1.0);
    let base = strip.positions.len() as u32;
    strip
        .positions
        .extend(right.positions.iter().map(|p| *p + Vec3::X));
    strip.normals.extend(&right.normals);
    strip.uvs.extend(&right.uvs);
    strip.tangents.extend(&right.tangents);
    strip.indices.extend(right.indices.iter().map(|i| i + base));
    let textures = [leaf_texture(LEAF_TEXTURE_SIZE)];
    let m = leaf_material(AlphaMode::Mask(0.5));
    assert!(trim(&strip, &AlphaCut::new(&m, &strip, &textures).unwrap()).is_none());
    // A ground of two triangles is one lone quad and is cut.
    let ground = plane(2.0, 1.0);
    assert!(trim(&ground, &AlphaCut::new(&m, &ground, &textures).unwrap()).is_some());
}
