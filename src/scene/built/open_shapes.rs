//! Open, organic meshes for benchmark scenes: surfaces whose edges are not closed (so back-face
//! culling of closed meshes does not apply), curved and rippled like scanned or sculpted models:
//! a vase of revolution without caps, a bent and twisted leaf, a rippled shell, a ribbon (an open
//! section of a torus). Each is a grid of `u × v` quads.

use crate::scene::built::shapes::{primitive_from_arrays, MeshArrays};
use crate::scene::Primitive;
use glam::Vec3;
use std::f32::consts::{PI, TAU};

/// A `u`×`v` quad grid of the surface `f(s, t)` (s, t in 0..1), two triangles a quad; normals
/// from the surface. Seams are not welded: the mesh stays open.
fn grid(u: u32, v: u32, f: impl Fn(f32, f32) -> Vec3) -> Primitive {
    let (u, v) = (u.max(1), v.max(1));
    let mut positions = Vec::with_capacity(((u + 1) * (v + 1)) as usize);
    let mut uvs = Vec::with_capacity(positions.capacity());
    for j in 0..=v {
        for i in 0..=u {
            let (s, t) = (i as f32 / u as f32, j as f32 / v as f32);
            positions.push(f(s, t).to_array());
            uvs.push([s, t]);
        }
    }
    let mut indices = Vec::with_capacity((u * v * 6) as usize);
    let at = |i: u32, j: u32| j * (u + 1) + i;
    for j in 0..v {
        for i in 0..u {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            indices.extend([a, b, c, a, c, d]);
        }
    }
    primitive_from_arrays(&MeshArrays {
        positions: &positions,
        indices: Some(&indices),
        normals: None,
        uvs: Some(&uvs),
        colors: None,
    })
    .expect("a finite grid")
}

/// A vase of revolution, `height` tall and about `radius` wide, its wall rippled (`lobes` lobes),
/// open at the top and the bottom.
pub fn vase(radius: f32, height: f32, lobes: f32, u: u32, v: u32) -> Primitive {
    grid(u, v, |s, t| {
        let a = s * TAU;
        let profile = 0.55 + 0.45 * (PI * (0.15 + 0.8 * t)).sin() - 0.2 * t;
        let r = radius * profile * (1.0 + 0.07 * (lobes * a + 4.0 * t).sin());
        Vec3::new(r * a.cos(), height * t, r * a.sin())
    })
}

/// A leaf `length` long and `width` wide along +X, bent down along its length, cupped across
/// it and twisted by `twist` radians from base to tip.
pub fn leaf(length: f32, width: f32, twist: f32, u: u32, v: u32) -> Primitive {
    grid(u, v, |s, t| {
        let half = 0.5 * width * (PI * s).sin().max(0.0).powf(0.7).max(0.01);
        let across = (2.0 * t - 1.0) * half;
        let cup = 0.5 * across * across / width;
        let (sin, cos) = (twist * s).sin_cos();
        Vec3::new(
            length * s,
            -0.35 * length * s * s + across * sin + cup * cos,
            across * cos - cup * sin,
        )
    })
}

/// A shell: a cap of a sphere of `radius` down to `opening` radians from its pole, its surface
/// rippled by `ribs` ribs, open at the rim.
pub fn shell(radius: f32, opening: f32, ribs: f32, u: u32, v: u32) -> Primitive {
    grid(u, v, |s, t| {
        let a = s * TAU;
        let polar = (t * opening).max(1e-3);
        let r = radius * (1.0 + 0.05 * (ribs * a).sin() * t);
        Vec3::new(
            r * polar.sin() * a.cos(),
            r * polar.cos(),
            r * polar.sin() * a.sin(),
        )
    })
}

/// A ribbon: `sweep` radians of a torus of radii `major`, `minor`, open at both ends and
/// along a slit of its tube (`tube` radians of the tube's 2π), undulating.
pub fn ribbon(major: f32, minor: f32, sweep: f32, tube: f32, u: u32, v: u32) -> Primitive {
    grid(u, v, |s, t| {
        let a = s * sweep;
        let b = t * tube;
        let m = minor * (1.0 + 0.15 * (3.0 * a).sin());
        let r = major + m * b.cos();
        Vec3::new(
            r * a.cos(),
            m * b.sin() + 0.1 * major * (2.0 * a).sin(),
            r * a.sin(),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::mesh::topology::is_closed;

    #[test]
    fn the_shapes_are_open_grids_of_the_asked_size() {
        for (name, p) in [
            ("vase", vase(1.0, 2.0, 5.0, 48, 32)),
            ("leaf", leaf(2.0, 0.8, 0.6, 48, 16)),
            ("shell", shell(1.0, 2.0, 12.0, 48, 24)),
            ("ribbon", ribbon(1.0, 0.3, 4.0, 5.0, 64, 16)),
        ] {
            assert!(
                !is_closed(&p.positions, &p.indices),
                "{name} must be an open mesh"
            );
            assert!(p.positions.iter().all(|q| q.is_finite()), "{name}");
            assert!(p.normals.iter().all(|n| n.is_finite()), "{name}");
        }
        assert_eq!(vase(1.0, 2.0, 5.0, 48, 32).indices.len(), 48 * 32 * 6);
    }
}
