//! Procedural meshes for the demo scene and tests, with normals, UVs and tangents.

use crate::scene::{Instance, Material, Mesh, Primitive, Scene, Texture};
use glam::{Mat4, Vec2, Vec3, Vec4};

fn prim(
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
    tangents: Vec<Vec4>,
    indices: Vec<u32>,
) -> Primitive {
    Primitive {
        positions,
        normals,
        uvs,
        tangents,
        indices,
        material: 0,
        has_uvs: true,
        colors: Vec::new(),
        uvs1: Vec::new(),
        deform: None,
    }
}

/// A square in the XZ plane centred at the origin, facing +Y, `size` wide, UVs repeating `uv_scale`
/// times (u along +X, v along +Z).
pub fn plane(size: f32, uv_scale: f32) -> Primitive {
    let h = size * 0.5;
    prim(
        vec![
            Vec3::new(-h, 0.0, -h),
            Vec3::new(h, 0.0, -h),
            Vec3::new(h, 0.0, h),
            Vec3::new(-h, 0.0, h),
        ],
        vec![Vec3::Y; 4],
        vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(uv_scale, 0.0),
            Vec2::new(uv_scale, uv_scale),
            Vec2::new(0.0, uv_scale),
        ],
        vec![Vec4::new(1.0, 0.0, 0.0, 1.0); 4],
        vec![0, 2, 1, 0, 3, 2],
    )
}

/// A rectangle in the XY plane centred at the origin, facing +Z; u along +X, v down (−Y), the
/// upright layout of an image on a wall.
pub fn quad(width: f32, height: f32) -> Primitive {
    let (w, h) = (width * 0.5, height * 0.5);
    prim(
        vec![
            Vec3::new(-w, -h, 0.0),
            Vec3::new(w, -h, 0.0),
            Vec3::new(w, h, 0.0),
            Vec3::new(-w, h, 0.0),
        ],
        vec![Vec3::Z; 4],
        vec![
            Vec2::new(0.0, 1.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(0.0, 0.0),
        ],
        // glTF: bitangent = w · (n × t) points up the image (towards decreasing v, the normal
        // map's +Y). Here n × t = Z × X = +Y is up, so w = +1.
        vec![Vec4::new(1.0, 0.0, 0.0, 1.0); 4],
        vec![0, 1, 2, 0, 2, 3],
    )
}

/// An axis-aligned box centred at the origin with the given half extents, 24 vertices.
pub fn cuboid(half: Vec3) -> Primitive {
    let mut p = Primitive {
        material: 0,
        has_uvs: true,
        ..Default::default()
    };
    // (normal, tangent) for each face; bitangent = n × t.
    let faces = [
        (Vec3::X, -Vec3::Z),
        (-Vec3::X, Vec3::Z),
        (Vec3::Y, Vec3::X),
        (-Vec3::Y, Vec3::X),
        (Vec3::Z, Vec3::X),
        (-Vec3::Z, -Vec3::X),
    ];
    for (n, t) in faces {
        let b = n.cross(t);
        let base = p.positions.len() as u32;
        for (su, sv) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            let corner = n + t * su + b * sv;
            p.positions.push(corner * half);
            p.normals.push(n);
            // v decreases along n × t (up the image), so w = +1 in glTF's convention.
            p.uvs.push(Vec2::new((su + 1.0) * 0.5, (1.0 - sv) * 0.5));
            p.tangents.push(t.extend(1.0));
        }
        p.indices
            .extend([base, base + 1, base + 2, base, base + 2, base + 3]);
    }
    p
}

/// A UV sphere of `radius` centred at the origin.
pub fn uv_sphere(radius: f32, segments: u32, rings: u32) -> Primitive {
    let mut p = Primitive {
        material: 0,
        has_uvs: true,
        ..Default::default()
    };
    for r in 0..=rings {
        let v = r as f32 / rings as f32;
        let theta = v * std::f32::consts::PI;
        for s in 0..=segments {
            let u = s as f32 / segments as f32;
            let phi = u * std::f32::consts::TAU;
            let n = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                -theta.sin() * phi.sin(),
            );
            p.positions.push(n * radius);
            p.normals.push(n);
            p.uvs.push(Vec2::new(u, v));
            let t = Vec3::new(-phi.sin(), 0.0, -phi.cos());
            p.tangents.push(t.extend(1.0));
        }
    }
    let row = segments + 1;
    for r in 0..rings {
        for s in 0..segments {
            let a = r * row + s;
            let b = a + row;
            if r != 0 {
                p.indices.extend([a, b, a + 1]);
            }
            if r != rings - 1 {
                p.indices.extend([a + 1, b, b + 1]);
            }
        }
    }
    p
}

/// A torus around +Y centred at the origin: tube centre circle of radius `major`, tube radius
/// `minor`, `segments` around the ring and `sides` around the tube.
pub fn torus(major: f32, minor: f32, segments: u32, sides: u32) -> Primitive {
    let mut p = Primitive {
        material: 0,
        has_uvs: true,
        ..Default::default()
    };
    for i in 0..=segments {
        let u = i as f32 / segments as f32;
        let phi = u * std::f32::consts::TAU;
        let (sp, cp) = phi.sin_cos();
        let ring = Vec3::new(cp, 0.0, -sp);
        for j in 0..=sides {
            let v = j as f32 / sides as f32;
            let theta = v * std::f32::consts::TAU;
            let n = ring * theta.cos() + Vec3::Y * theta.sin();
            p.positions.push(ring * major + n * minor);
            p.normals.push(n);
            p.uvs.push(Vec2::new(u, v));
            p.tangents.push(Vec3::new(-sp, 0.0, -cp).extend(1.0));
        }
    }
    let row = sides + 1;
    for i in 0..segments {
        for j in 0..sides {
            let a = i * row + j;
            let b = a + row;
            p.indices.extend([a, a + 1, b, b, a + 1, b + 1]);
        }
    }
    p
}

/// Appends a single-primitive mesh with its own material and one instance; returns the mesh index.
pub fn add_object(
    scene: &mut Scene,
    name: &str,
    mut p: Primitive,
    material: Material,
    world_from_model: Mat4,
) -> usize {
    scene.materials.push(material);
    p.material = scene.materials.len() - 1;
    scene.meshes.push(Mesh {
        name: name.into(),
        primitives: vec![p],
    });
    scene.instances.push(Instance {
        mesh: scene.meshes.len() - 1,
        world_from_model,
        node: None,
    });
    scene.meshes.len() - 1
}

/// A triangle mesh as arrays (what the Python package's `Scene.add_mesh` takes): positions, and
/// optionally indices (a triangle list; without, every three positions are a triangle), normals,
/// texture coordinates and linear RGBA vertex colours, each with one entry per position.
#[derive(Clone, Copy, Debug, Default)]
pub struct MeshArrays<'a> {
    /// Object-space positions.
    pub positions: &'a [[f32; 3]],
    /// Triangle-list indices into `positions`.
    pub indices: Option<&'a [u32]>,
    /// Vertex normals (need not be unit length; smooth normals are computed without them).
    pub normals: Option<&'a [[f32; 3]]>,
    /// TEXCOORD_0.
    pub uvs: Option<&'a [[f32; 2]]>,
    /// Linear RGBA colours multiplying the base colour.
    pub colors: Option<&'a [[f32; 4]]>,
}

/// The primitive of `a` (normals computed when absent, tangents from the normals), or a
/// one-line reason it cannot be one: no positions, a non-finite value, an index past the
/// positions, a count that is not a whole number of triangles, or an attribute whose count
/// differs from the positions'.
pub fn primitive_from_arrays(a: &MeshArrays) -> Result<Primitive, String> {
    let n = a.positions.len();
    if n == 0 {
        return Err("positions are empty".into());
    }
    let finite = |v: &[f32]| v.iter().all(|x| x.is_finite());
    if !a.positions.iter().all(|p| finite(p)) {
        return Err("positions hold a NaN or an infinity".into());
    }
    let indices: Vec<u32> = match a.indices {
        Some(i) => i.to_vec(),
        None => (0..n as u32).collect(),
    };
    if indices.len() % 3 != 0 || indices.is_empty() {
        return Err(format!(
            "{} indices are not a whole number of triangles",
            indices.len()
        ));
    }
    if let Some(bad) = indices.iter().find(|&&i| i as usize >= n) {
        return Err(format!("index {bad} is past the {n} positions"));
    }
    let count = |name: &str, len: Option<usize>| match len {
        Some(m) if m != n => Err(format!("{m} {name} for {n} positions")),
        _ => Ok(()),
    };
    count("normals", a.normals.map(<[_]>::len))?;
    count("texture coordinates", a.uvs.map(<[_]>::len))?;
    count("colours", a.colors.map(<[_]>::len))?;
    let positions: Vec<Vec3> = a.positions.iter().map(|&p| Vec3::from_array(p)).collect();
    let normals = match a.normals {
        Some(v) if v.iter().all(|p| finite(p)) => v
            .iter()
            .map(|&p| Vec3::from_array(p).try_normalize().unwrap_or(Vec3::Y))
            .collect(),
        Some(_) => return Err("normals hold a NaN or an infinity".into()),
        None => crate::scene::mesh::tangents::compute_smooth_normals(&positions, &indices),
    };
    let uvs: Vec<Vec2> = a
        .uvs
        .map(|v| v.iter().map(|&t| Vec2::from_array(t)).collect())
        .unwrap_or_else(|| vec![Vec2::ZERO; n]);
    let tangents = normals
        .iter()
        .map(|&m| crate::scene::mesh::tangents::fallback_tangent(m))
        .collect();
    let mut p = prim(positions, normals, uvs, tangents, indices);
    p.has_uvs = a.uvs.is_some();
    p.colors = a
        .colors
        .map(|c| c.iter().map(|&c| Vec4::from_array(c)).collect())
        .unwrap_or_default();
    Ok(p)
}

/// Adds a texture and returns its index.
pub fn add_texture(scene: &mut Scene, t: Texture) -> usize {
    scene.textures.push(t);
    scene.textures.len() - 1
}

/// A plain material of linear colour `rgb`.
pub fn colored(rgb: Vec3, roughness: f32) -> Material {
    Material {
        name: format!("{rgb}"),
        base_color: rgb.extend(1.0),
        roughness,
        ..Default::default()
    }
}

/// Adds a grey ground plane just under the scene's bounds (for an animated scene, under the
/// lowest point any animation reaches), wide enough to catch its shadows (5× the bounds'
/// diagonal), for viewing models that have none.
pub fn add_ground(scene: &mut Scene) {
    let b = scene.bounds();
    if b.is_empty() {
        return;
    }
    let size = (b.diagonal() * 5.0).max(1e-3);
    // Under the lowest point the model reaches in any of its animations, so a foot that dips
    // below the rest pose's lowest point does not pass through the ground.
    let low = if scene.moves() {
        scene.motion_bounds(32).min.y
    } else {
        b.min.y
    };
    let y = low - b.diagonal() * 1e-3;
    let c = b.center();
    scene.framing.get_or_insert(b);
    add_object(
        scene,
        "ground",
        plane(size, 1.0),
        colored(Vec3::splat(0.3), 0.9),
        Mat4::from_translation(Vec3::new(c.x, y, c.z)),
    );
}

#[cfg(test)]
mod array_tests {
    use super::*;

    #[test]
    fn arrays_make_a_primitive_or_a_one_line_reason() {
        let tri = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let p = primitive_from_arrays(&MeshArrays {
            positions: &tri,
            ..Default::default()
        })
        .unwrap();
        assert_eq!(p.indices, [0, 1, 2]);
        assert!(p.normals.iter().all(|n| n.abs_diff_eq(Vec3::Z, 1e-6)));
        assert_eq!(p.tangents.len(), 3);
        for (a, want) in [
            (
                MeshArrays {
                    positions: &tri,
                    indices: Some(&[0, 1, 3]),
                    ..Default::default()
                },
                "index 3 is past the 3 positions",
            ),
            (
                MeshArrays {
                    positions: &tri,
                    indices: Some(&[0, 1]),
                    ..Default::default()
                },
                "2 indices are not a whole number of triangles",
            ),
            (
                MeshArrays {
                    positions: &tri,
                    normals: Some(&[[0.0, 0.0, 1.0]]),
                    ..Default::default()
                },
                "1 normals for 3 positions",
            ),
            (
                MeshArrays {
                    positions: &[[f32::NAN, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
                    ..Default::default()
                },
                "positions hold a NaN or an infinity",
            ),
        ] {
            assert_eq!(primitive_from_arrays(&a).unwrap_err(), want);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check_winding(p: &Primitive) {
        for t in p.indices.chunks_exact(3) {
            let (a, b, c) = (
                p.positions[t[0] as usize],
                p.positions[t[1] as usize],
                p.positions[t[2] as usize],
            );
            let face_n = (b - a).cross(c - a);
            let n = p.normals[t[0] as usize] + p.normals[t[1] as usize] + p.normals[t[2] as usize];
            assert!(
                face_n.dot(n) > 0.0,
                "triangle {t:?} winds against its normal"
            );
        }
    }

    fn check_tangents(p: &Primitive) {
        // Tangent along +u, w·(n × t) along −v (up the image), measured on each triangle.
        for t in p.indices.chunks_exact(3) {
            let i = [t[0] as usize, t[1] as usize, t[2] as usize];
            let (e1, e2) = (
                p.positions[i[1]] - p.positions[i[0]],
                p.positions[i[2]] - p.positions[i[0]],
            );
            let (d1, d2) = (p.uvs[i[1]] - p.uvs[i[0]], p.uvs[i[2]] - p.uvs[i[0]]);
            let r = d1.x * d2.y - d2.x * d1.y;
            if r.abs() < 1e-8 {
                continue;
            }
            let tu = (e1 * d2.y - e2 * d1.y) / r;
            let tv = (e2 * d1.x - e1 * d2.x) / r;
            let tan = p.tangents[i[0]];
            let b = p.normals[i[0]].cross(tan.truncate()) * tan.w;
            assert!(tan.truncate().dot(tu) > 0.0, "tangent against +u");
            assert!(b.dot(tv) < 0.0, "bitangent must point up the image (−v)");
        }
    }

    #[test]
    fn shapes_wind_ccw_with_consistent_tangents() {
        for p in [
            plane(4.0, 2.0),
            quad(2.0, 1.0),
            cuboid(Vec3::new(1.0, 2.0, 3.0)),
            uv_sphere(1.0, 16, 8),
        ] {
            check_winding(&p);
            check_tangents(&p);
            assert_eq!(p.positions.len(), p.normals.len());
            assert_eq!(p.positions.len(), p.uvs.len());
            assert_eq!(p.positions.len(), p.tangents.len());
        }
    }
}
