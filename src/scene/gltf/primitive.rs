//! One glTF mesh primitive into the scene's: positions, triangles (strips and fans as lists),
//! normals, texture coordinates, colours, tangents and morph/skin data, each checked, with a
//! finding for each repair.

use super::error::{corrupt, LoadError};
use super::input::check_attribute_types;
use crate::scene::mesh::mikk::generate_mikktspace;
use crate::scene::mesh::tangents::{compute_smooth_normals, count_degenerate, fallback_tangent};
use crate::scene::{Primitive, Scene};
use glam::{Vec2, Vec3, Vec4};
use std::path::Path;

/// How far from 1 a stored normal's or tangent's length may be (glTF-Validator allows 4e-3;
/// quantised normals land within it).
const UNIT_TOLERANCE: f32 = 4e-3;

/// Whether a stored vector's length is 1 within `UNIT_TOLERANCE` plus the rounding `slack` of a
/// quantized accessor (NaN is not).
fn unit_length(len: f32, slack: f32) -> bool {
    (len - 1.0).abs() <= UNIT_TOLERANCE + slack
}

/// Warns when a POSITION accessor's declared min/max (required by glTF) differ from its data.
fn check_min_max(scene: &mut Scene, acc: &gltf::Accessor, positions: &[Vec3]) {
    let declared = |v: Option<gltf::json::Value>| -> Option<Vec3> {
        let a = v?
            .as_array()?
            .iter()
            .map(|x| x.as_f64())
            .collect::<Option<Vec<f64>>>()?;
        (a.len() == 3).then(|| Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32))
    };
    let (Some(lo), Some(hi)) = (declared(acc.min()), declared(acc.max())) else {
        return;
    };
    let finite = positions.iter().filter(|p| p.is_finite());
    let (dlo, dhi) = finite.fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(a, b), p| (a.min(*p), b.max(*p)),
    );
    if dlo.x > dhi.x {
        return;
    }
    // Declared values are decimal text: allow a relative 1e-5 of the extent.
    let tol = ((dhi - dlo).max_element() * 1e-5).max(1e-6);
    let off = (lo - dlo).abs().max((hi - dhi).abs()).max_element();
    if off > tol {
        scene.warn(
            "ACCESSOR_MIN_MAX_MISMATCH",
            format!("/accessors/{}", acc.index()),
            format!(
                "accessor {}: declared POSITION bounds [{lo}, {hi}] differ from the data's \
                 [{dlo}, {dhi}] (by {off:.3e}); umbra uses the data",
                acc.index()
            ),
        );
    }
}

pub(super) fn read_primitive(
    path: &Path,
    scene: &mut Scene,
    buffers: &[Vec<u8>],
    mesh: &gltf::Mesh,
    prim: &gltf::Primitive,
    default_material: usize,
) -> Result<Option<Primitive>, LoadError> {
    let label = format!("mesh {} primitive {}", mesh.index(), prim.index());
    let at = format!("/meshes/{}/primitives/{}", mesh.index(), prim.index());
    check_attribute_types(path, &label, prim)?;
    let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d[..]));
    let Some(positions) = reader.read_positions() else {
        scene.warn(
            "MESH_NO_POSITION",
            at,
            format!("{label} has no POSITION; skipped"),
        );
        return Ok(None);
    };
    let positions: Vec<Vec3> = positions.map(Vec3::from_array).collect();
    let n = positions.len();
    let slack = |s: gltf::Semantic| {
        prim.get(&s)
            .map_or(0.0, |a| scene.compression.unit_slack(a.index()))
    };
    let site = Site {
        at: &at,
        label: &label,
        n,
        slack: slack(gltf::Semantic::Normals).max(slack(gltf::Semantic::Tangents)),
    };
    if let Some(acc) = prim.get(&gltf::Semantic::Positions) {
        check_min_max(scene, &acc, &positions);
    }
    if prim.attributes().any(|(_, a)| a.count() != n) {
        return Err(corrupt(path, format!("{label}: attribute counts differ")));
    }
    let raw_indices = read_indices(path, &reader, &site)?;
    let Some(indices) = triangle_list(prim.mode(), &raw_indices) else {
        scene.warn(
            "MESH_UNSUPPORTED_MODE",
            at,
            format!(
                "{label}: mode {:?} is not drawn (triangles only)",
                prim.mode()
            ),
        );
        return Ok(None);
    };
    let indices = finite_triangles(scene, &site, &positions, indices);
    let has_normals = prim.get(&gltf::Semantic::Normals).is_some();
    let normals = read_normals(scene, &reader, &site, &positions, &indices);
    let (uvs, has_uvs) = read_uvs0(&reader, n);
    let uvs1 = read_uvs1(scene, &reader, &site);
    let colors = read_colors(scene, &reader, &site);
    let deform = crate::scene::anim::load::read_deform(scene, &reader, n, &at, &label);
    let material = prim.material().index().unwrap_or(default_material);
    let mut p = Primitive {
        positions,
        normals,
        uvs,
        tangents: Vec::new(),
        indices,
        material,
        has_uvs,
        colors,
        uvs1,
        deform: deform.map(Box::new),
    };
    tangents_and_normal_map(scene, &reader, &site, &mut p);
    if let Some(d) = p.deform.as_deref_mut() {
        d.positions = p.positions.clone();
        d.normals = p.normals.clone();
        d.tangents = p.tangents.clone();
        d.normals_computed = !has_normals;
    }
    Ok(Some(p))
}

/// The primitive's tangents: stored, else MikkTSpace where its material has a normal map and it
/// has texture coordinates, else a fallback per normal. A normal map without texture
/// coordinates is dropped (the primitive gets a copy of its material without it).
fn tangents_and_normal_map<'a, 's, F>(
    scene: &mut Scene,
    reader: &gltf::mesh::Reader<'a, 's, F>,
    site: &Site,
    p: &mut Primitive,
) where
    F: Clone + Fn(gltf::Buffer<'a>) -> Option<&'s [u8]>,
{
    let (at, label, material, has_uvs) = (site.at.to_string(), site.label, p.material, p.has_uvs);
    let wants_normal_map = scene.materials[material].normal_texture.is_some();
    match reader.read_tangents() {
        Some(it) => p.tangents = stored_tangents(scene, site, it),
        None if wants_normal_map && has_uvs => {
            if !generate_mikktspace(p) {
                scene.warn(
                    "MESH_TANGENTS_FAILED",
                    at.clone(),
                    format!(
                        "{label}: MikkTSpace tangent generation failed; normal map may be wrong"
                    ),
                );
            }
        }
        None => p.tangents = p.normals.iter().map(|n| fallback_tangent(*n)).collect(),
    }
    if wants_normal_map && !has_uvs {
        scene.warn(
            "NORMAL_MAP_WITHOUT_UVS",
            at,
            format!("{label}: normal map ignored: the primitive has no TEXCOORD_0"),
        );
        let mut m = scene.materials[material].clone();
        m.normal_texture = None;
        m.name = format!("{} (no UVs)", m.name);
        scene.materials.push(m);
        p.material = scene.materials.len() - 1;
    }
}

/// TEXCOORD_0 (non-finite values as 0), and whether the primitive has it (zeros if not).
fn read_uvs0<'a, 's, F>(reader: &gltf::mesh::Reader<'a, 's, F>, n: usize) -> (Vec<Vec2>, bool)
where
    F: Clone + Fn(gltf::Buffer<'a>) -> Option<&'s [u8]>,
{
    match reader.read_tex_coords(0) {
        Some(it) => (
            it.into_f32()
                .map(|v| {
                    let v = Vec2::from_array(v);
                    if v.is_finite() {
                        v
                    } else {
                        Vec2::ZERO
                    }
                })
                .collect(),
            true,
        ),
        None => (vec![Vec2::ZERO; n], false),
    }
}

/// Where a primitive's findings point, and its vertex count.
struct Site<'a> {
    at: &'a str,
    label: &'a str,
    n: usize,
    /// How far quantized normals and tangents may be from unit length by rounding alone.
    slack: f32,
}

/// The triangles of a triangle list, strip or fan as a list; `None` for points and lines.
fn triangle_list(mode: gltf::mesh::Mode, raw: &[u32]) -> Option<Vec<u32>> {
    use gltf::mesh::Mode;
    Some(match mode {
        Mode::Triangles => raw.chunks_exact(3).flatten().copied().collect(),
        Mode::TriangleStrip => (2..raw.len())
            .flat_map(|i| {
                if i % 2 == 0 {
                    [raw[i - 2], raw[i - 1], raw[i]]
                } else {
                    [raw[i - 1], raw[i - 2], raw[i]]
                }
            })
            .collect(),
        Mode::TriangleFan => (2..raw.len())
            .flat_map(|i| [raw[0], raw[i - 1], raw[i]])
            .collect(),
        _ => return None,
    })
}

/// `indices` without the triangles touching non-finite positions (a warning when some are
/// dropped), and a warning for zero-area triangles.
fn finite_triangles(
    scene: &mut Scene,
    site: &Site,
    positions: &[Vec3],
    indices: Vec<u32>,
) -> Vec<u32> {
    let (at, label) = (site.at, site.label);
    let before = indices.len() / 3;
    let indices: Vec<u32> = indices
        .chunks_exact(3)
        .filter(|t| t.iter().all(|&i| positions[i as usize].is_finite()))
        .flatten()
        .copied()
        .collect();
    if indices.len() / 3 != before {
        scene.warn(
            "MESH_NONFINITE_POSITIONS",
            at,
            format!(
                "{label}: {} triangles with non-finite positions dropped",
                before - indices.len() / 3
            ),
        );
    }
    let degenerate = count_degenerate(positions, &indices);
    if degenerate > 0 {
        scene.warn(
            "MESH_DEGENERATE_TRIANGLES",
            at,
            format!("{label}: {degenerate} zero-area triangles"),
        );
    }
    indices
}

/// The stored normals, normalised (a warning for those not of unit length), or smooth normals
/// computed from the triangles when there are none.
fn read_normals<'a, 's, F>(
    scene: &mut Scene,
    reader: &gltf::mesh::Reader<'a, 's, F>,
    site: &Site,
    positions: &[Vec3],
    indices: &[u32],
) -> Vec<Vec3>
where
    F: Clone + Fn(gltf::Buffer<'a>) -> Option<&'s [u8]>,
{
    let (at, label, n) = (site.at, site.label, site.n);
    match reader.read_normals() {
        Some(it) => {
            let mut off_unit = 0usize;
            let normals = it
                .map(|v| {
                    let v = Vec3::from_array(v);
                    if !unit_length(v.length(), site.slack) {
                        off_unit += 1;
                    }
                    v.try_normalize().unwrap_or(Vec3::Y)
                })
                .collect();
            if off_unit > 0 {
                scene.warn(
                    "MESH_NORMALS_NOT_UNIT",
                    format!("{at}/attributes/NORMAL"),
                    format!(
                        "{label}: {off_unit} of {n} normals are not unit length (|n| off 1 by \
                         more than {}); normalised",
                        UNIT_TOLERANCE + site.slack
                    ),
                );
            }
            normals
        }
        None => {
            scene.warn(
                "MESH_NORMALS_MISSING",
                at,
                format!("{label}: no normals; computed smooth normals"),
            );
            compute_smooth_normals(positions, indices)
        }
    }
}

/// TEXCOORD_1, for slots that read it (non-finite values read as 0); empty without one, or
/// (with a warning) when its count differs from the vertices'.
fn read_uvs1<'a, 's, F>(
    scene: &mut Scene,
    reader: &gltf::mesh::Reader<'a, 's, F>,
    site: &Site,
) -> Vec<Vec2>
where
    F: Clone + Fn(gltf::Buffer<'a>) -> Option<&'s [u8]>,
{
    let (at, label, n) = (site.at, site.label, site.n);
    let uvs1: Vec<Vec2> = match reader.read_tex_coords(1) {
        Some(it) => it
            .into_f32()
            .map(Vec2::from_array)
            .map(|v| if v.is_finite() { v } else { Vec2::ZERO })
            .collect(),
        None => Vec::new(),
    };
    if uvs1.is_empty() || uvs1.len() == n {
        uvs1
    } else {
        scene.warn(
            "TEXCOORD_FALLBACK",
            at,
            format!(
                "{label}: TEXCOORD_1 has {} values for {n} vertices; set 0 read instead",
                uvs1.len()
            ),
        );
        Vec::new()
    }
}

/// COLOR_0, which multiplies the base colour (RGB gets alpha 1; NaN reads as white); empty
/// without one, or (with a warning) when its count differs from the vertices'.
fn read_colors<'a, 's, F>(
    scene: &mut Scene,
    reader: &gltf::mesh::Reader<'a, 's, F>,
    site: &Site,
) -> Vec<Vec4>
where
    F: Clone + Fn(gltf::Buffer<'a>) -> Option<&'s [u8]>,
{
    let (at, label, n) = (site.at, site.label, site.n);
    match reader.read_colors(0) {
        Some(c) => {
            let c: Vec<Vec4> = c
                .into_rgba_f32()
                .map(|c| Vec4::from_array(c).clamp(Vec4::ZERO, Vec4::ONE))
                .map(|c| if c.is_nan() { Vec4::ONE } else { c })
                .collect();
            if c.len() == n {
                c
            } else {
                scene.warn(
                    "MESH_COLORS_IGNORED",
                    at,
                    format!(
                        "{label}: COLOR_0 has {} values for {n} vertices, ignored",
                        c.len()
                    ),
                );
                Vec::new()
            }
        }
        None => Vec::new(),
    }
}

/// The stored tangents: xyz normalised, w's sign kept (a warning for those that needed it);
/// unusable ones read as +X.
fn stored_tangents(
    scene: &mut Scene,
    site: &Site,
    it: impl Iterator<Item = [f32; 4]>,
) -> Vec<Vec4> {
    let (at, label, n) = (site.at, site.label, site.n);
    let (mut bad_w, mut off_unit) = (0usize, 0usize);
    let tangents: Vec<Vec4> = it
        .map(|t| {
            let t = Vec4::from_array(t);
            bad_w += (t.w != 1.0 && t.w != -1.0) as usize;
            off_unit += !unit_length(t.truncate().length(), site.slack) as usize;
            if t.is_finite() && t.truncate().length_squared() > 1e-12 {
                t.truncate()
                    .normalize()
                    .extend(if t.w < 0.0 { -1.0 } else { 1.0 })
            } else {
                Vec4::new(1.0, 0.0, 0.0, 1.0)
            }
        })
        .collect();
    if bad_w > 0 || off_unit > 0 {
        scene.warn(
            "MESH_TANGENTS_INVALID",
            format!("{at}/attributes/TANGENT"),
            format!(
                "{label}: of {n} tangents, {bad_w} have w other than ±1 (the sign is \
                 kept) and {off_unit} xyz not of unit length (normalised)"
            ),
        );
    }
    tangents
}

/// The primitive's indices (0..n without an index accessor), each checked against the vertex
/// count.
fn read_indices<'a, 's, F>(
    path: &Path,
    reader: &gltf::mesh::Reader<'a, 's, F>,
    site: &Site,
) -> Result<Vec<u32>, LoadError>
where
    F: Clone + Fn(gltf::Buffer<'a>) -> Option<&'s [u8]>,
{
    let (label, n) = (site.label, site.n);
    let raw_indices: Vec<u32> = match reader.read_indices() {
        Some(i) => i.into_u32().collect(),
        None => (0..n as u32).collect(),
    };
    if let Some(bad) = raw_indices.iter().find(|&&i| i as usize >= n) {
        return Err(corrupt(
            path,
            format!("{label}: index {bad} out of range (vertex count {n})"),
        ));
    }
    Ok(raw_indices)
}
