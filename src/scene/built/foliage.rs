//! The foliage test scene, generated here: trees whose crowns are textured leaf cards (a cluster
//! of leaves drawn into the alpha channel of a generated texture, double-sided), over a ground,
//! under a sun 45° high, seen from a metre above the ground: the scene where a shadow map's
//! texels are coarser than the shadows they must draw. Two variants: leaves alpha-blended (as
//! such files often mark them) and alpha-masked at 0.5.

use crate::scene::built::shapes::{add_object, add_texture, colored, cuboid, plane};
use crate::scene::{AlphaMode, Camera, Light, Material, Primitive, Scene, Texture, TextureRef};
use glam::{Mat4, Quat, Vec2, Vec3, Vec4};

/// Side of the leaf texture in texels.
pub const LEAF_TEXTURE_SIZE: u32 = 128;

/// Signed distance (in uv units, negative inside) to a leaf of the cluster: five pointed
/// ellipses radiating from the bottom centre of the card, with a stem.
fn leaf_distance(p: Vec2) -> f32 {
    let base = Vec2::new(0.5, 0.95);
    let mut d = f32::INFINITY;
    for (angle, length) in [
        (-70f32, 0.36),
        (-35.0, 0.44),
        (0.0, 0.5),
        (35.0, 0.44),
        (70.0, 0.36),
    ] {
        let (s, c) = angle.to_radians().sin_cos();
        // Leaf frame: `along` from the base out to the tip, `across` at right angles.
        let q = p - base;
        let along = -q.y * c + q.x * s;
        let across = q.x * c + q.y * s;
        let t = (along / length).clamp(0.0, 1.0);
        // Half-width of a lanceolate leaf at t: zero at both ends, widest at 40 %.
        let half = 0.22 * length * (std::f32::consts::PI * t.powf(0.8)).sin();
        let beyond = (along - along.clamp(0.0, length)).abs();
        d = d.min(across.abs() - half + beyond);
    }
    // The stem: a thin segment from the base down to the card's edge.
    let stem = (p.x - 0.5).abs() - 0.008;
    if p.y > base.y {
        d = d.min(stem);
    }
    d
}

/// The leaf cluster texture: sRGB greens in RGB, the leaves' coverage in alpha (a ramp one and
/// a half texels wide across each outline, so alpha crosses every cutoff between 0 and 1).
pub fn leaf_texture(size: u32) -> Texture {
    let mut rgba = Vec::with_capacity((size * size * 4) as usize);
    for y in 0..size {
        for x in 0..size {
            let p = Vec2::new(
                (x as f32 + 0.5) / size as f32,
                (y as f32 + 0.5) / size as f32,
            );
            let d = leaf_distance(p) * size as f32;
            let alpha = (0.5 - d / 1.5).clamp(0.0, 1.0);
            let shade = 0.75 + 0.25 * ((p.x * 37.0).sin() * (p.y * 23.0).cos());
            rgba.extend([
                (60.0 * shade) as u8,
                (130.0 * shade) as u8,
                (40.0 * shade) as u8,
                (alpha * 255.0).round() as u8,
            ]);
        }
    }
    Texture {
        name: "leaf cluster".into(),
        width: size,
        height: size,
        rgba,
        ktx2: None,
    }
}

/// A deterministic generator (a 64-bit LCG), so the scene is the same on every machine.
struct Lcg(u64);

impl Lcg {
    /// A number in [0, 1).
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// `cards` square cards `size` wide, scattered through an ellipsoid crown of radii `radii`
/// around the origin, each turned at random, merged into one primitive.
fn crown(rng: &mut Lcg, cards: u32, size: f32, radii: Vec3) -> Primitive {
    let card = crate::scene::built::shapes::quad(size, size);
    let mut out = Primitive {
        has_uvs: true,
        ..Default::default()
    };
    for _ in 0..cards {
        // A point inside the unit ball by rejection, then scaled to the crown.
        let mut p;
        loop {
            p = Vec3::new(rng.next(), rng.next(), rng.next()) * 2.0 - Vec3::ONE;
            if p.length_squared() <= 1.0 {
                break;
            }
        }
        let q = Quat::from_euler(
            glam::EulerRot::YXZ,
            rng.next() * std::f32::consts::TAU,
            (rng.next() - 0.5) * 2.4,
            rng.next() * std::f32::consts::TAU,
        );
        let m = Mat4::from_rotation_translation(q, p * radii);
        let first = out.positions.len() as u32;
        out.positions
            .extend(card.positions.iter().map(|&v| m.transform_point3(v)));
        out.normals
            .extend(card.normals.iter().map(|&n| m.transform_vector3(n)));
        out.uvs.extend(&card.uvs);
        out.tangents.extend(
            card.tangents
                .iter()
                .map(|t| m.transform_vector3(t.truncate()).extend(t.w)),
        );
        out.indices.extend(card.indices.iter().map(|i| first + i));
    }
    out
}

/// Tree positions (x, z) and crown sizes of the foliage scene.
const TREES: [(f32, f32, f32); 6] = [
    (-3.0, -2.0, 1.6),
    (2.5, -4.0, 1.9),
    (-6.0, -8.0, 2.2),
    (5.5, -9.0, 2.0),
    (0.0, -12.0, 2.4),
    (-9.0, -3.0, 1.8),
];

/// Leaf cards per tree.
pub const FOLIAGE_CARDS_PER_TREE: u32 = 240;

/// The foliage scene (`--synthetic foliage`, leaves blended; `foliage-masked`, leaves masked at
/// 0.5): a 60 m ground, six trees of a trunk and [`FOLIAGE_CARDS_PER_TREE`] leaf cards, a sun
/// 45° high, the camera 1 m above the ground looking into the trees.
pub fn foliage_scene(alpha_mode: AlphaMode) -> Scene {
    let name = match alpha_mode {
        AlphaMode::Blend => "foliage",
        _ => "foliage-masked",
    };
    let mut s = Scene {
        name: name.into(),
        ..Default::default()
    };
    add_object(
        &mut s,
        "ground",
        plane(60.0, 1.0),
        colored(Vec3::new(0.35, 0.42, 0.25), 0.8),
        Mat4::IDENTITY,
    );
    let leaves = add_texture(&mut s, leaf_texture(LEAF_TEXTURE_SIZE));
    let leaf = Material {
        name: "leaves".into(),
        base_color: Vec4::ONE,
        base_color_texture: Some(TextureRef::new(leaves)),
        roughness: 0.7,
        alpha_mode,
        double_sided: true,
        ..Default::default()
    };
    let mut rng = Lcg(0x5eed_f011_a6e5);
    for (i, &(x, z, r)) in TREES.iter().enumerate() {
        let height = 1.4 * r;
        add_object(
            &mut s,
            &format!("trunk {i}"),
            cuboid(Vec3::new(0.12, height * 0.5, 0.12) * (r / 2.0)),
            colored(Vec3::new(0.25, 0.17, 0.1), 0.9),
            Mat4::from_translation(Vec3::new(x, height * 0.5 * r / 2.0, z)),
        );
        add_object(
            &mut s,
            &format!("crown {i}"),
            crown(
                &mut rng,
                FOLIAGE_CARDS_PER_TREE,
                0.7,
                Vec3::new(r, r * 0.8, r),
            ),
            leaf.clone(),
            Mat4::from_translation(Vec3::new(x, height * r / 2.0 + r * 0.5, z)),
        );
    }
    s.lights
        .push(Light::sun(Vec3::new(-0.5, -1.0 / 2f32.sqrt(), -0.5), 2.0));
    s.cameras.push(Camera::look_at(
        Vec3::new(0.5, 1.0, 4.5),
        Vec3::new(-1.0, 1.5, -4.0),
        60f32.to_radians(),
        0.1,
    ));
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn leaf_texture_covers_part_of_the_card_and_crosses_every_cutoff() {
        let t = leaf_texture(LEAF_TEXTURE_SIZE);
        let alphas: Vec<u8> = t.rgba.chunks(4).map(|p| p[3]).collect();
        let n = alphas.len() as f32;
        let opaque = alphas.iter().filter(|&&a| a == 255).count() as f32 / n;
        let clear = alphas.iter().filter(|&&a| a == 0).count() as f32 / n;
        let between = alphas.iter().filter(|&&a| a > 0 && a < 255).count();
        // Measured: 17.7 % opaque, 79.7 % clear, 426 texels in between (the outlines).
        assert!((0.15..0.21).contains(&opaque), "{opaque} opaque");
        assert!((0.77..0.82).contains(&clear), "{clear} clear");
        assert!(between > 350, "{between} texels between 0 and 1");
    }

    #[test]
    fn foliage_scene_has_six_crowns_of_cards_above_the_ground() {
        for mode in [AlphaMode::Blend, AlphaMode::Mask(0.5)] {
            let s = foliage_scene(mode);
            let crowns = s.meshes.iter().filter(|m| m.name.starts_with("crown"));
            assert_eq!(crowns.count(), TREES.len());
            assert_eq!(
                s.triangle_count(),
                2 + TREES.len() * (12 + 2 * FOLIAGE_CARDS_PER_TREE as usize)
            );
            let lowest_leaf = s
                .instances
                .iter()
                .filter(|i| s.meshes[i.mesh].name.starts_with("crown"))
                .flat_map(|i| {
                    s.meshes[i.mesh].primitives[0]
                        .positions
                        .iter()
                        .map(|p| i.world_from_model.transform_point3(*p).y)
                })
                .fold(f32::INFINITY, f32::min);
            assert!(lowest_leaf > 0.5, "lowest leaf at {lowest_leaf} m");
        }
    }
}
