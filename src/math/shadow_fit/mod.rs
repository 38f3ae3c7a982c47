//! Fitting a light's projection to what matters ("model no more than a scene needs").
//!
//! Directional lights: the orthographic light frustum covers the receivers the camera can see
//! (camera frustum ∩ scene bounds, computed exactly by clipping the two convex solids against each
//! other) and reaches towards the light far enough to include every caster in the scene bounds.
//! With `snap`, the square extent is quantised to steps of 2^(1/8) (`extent_steps`: steps per
//! doubling) and the origin is snapped to
//! whole shadow texels in a light space that only rotates with the light, so camera motion moves
//! the map by whole texels and shadow edges do not shimmer between the extent's steps. With
//! `sphere`, the map covers the bounding sphere of the camera's frustum instead (stable cascades):
//! its size no longer follows where the camera is or looks, so it steps far less often, for
//! coarser texels.

use super::projection::{orthographic_reversed, perspective_infinite_reversed};
use super::Aabb;
use glam::{Mat4, Vec3, Vec4};

/// A camera frustum to fit against: at view depth d it spans ±h(d) vertically and ±h(d)·aspect
/// horizontally, with h(d) = `half_height` + `tan_half`·d (a perspective camera: `half_height`
/// 0, `tan_half` = tan(fov_y / 2); an orthographic one: `tan_half` 0, `half_height` its ymag).
#[derive(Clone, Copy, Debug)]
pub struct CameraFrustum {
    /// World → view (right-handed, looking down −Z).
    pub view_from_world: Mat4,
    /// Growth of the half-height with depth (tan of half the vertical field of view; 0 for a
    /// parallel projection).
    pub tan_half: f32,
    /// Half-height at depth 0 (an orthographic camera's ymag; 0 for a perspective one).
    pub half_height: f32,
    /// Width / height.
    pub aspect: f32,
    /// Near distance.
    pub near: f32,
    /// Far distance (use the scene's extent for an infinite projection).
    pub far: f32,
}

impl CameraFrustum {
    /// A perspective frustum (`fov_y` in radians).
    pub fn perspective(
        view_from_world: Mat4,
        fov_y: f32,
        aspect: f32,
        near: f32,
        far: f32,
    ) -> Self {
        Self {
            view_from_world,
            tan_half: (fov_y * 0.5).tan(),
            half_height: 0.0,
            aspect,
            near,
            far,
        }
    }

    /// Half the height of the frustum's cross-section at view depth `d`.
    pub fn half_height_at(&self, d: f32) -> f32 {
        self.half_height + self.tan_half * d
    }

    /// The 8 corners in world space: near plane first (−−, +−, −+, ++ in x/y), then far.
    pub fn corners(&self) -> [Vec3; 8] {
        let world_from_view = self.view_from_world.inverse();
        let mut out = [Vec3::ZERO; 8];
        for (i, d) in [self.near, self.far].into_iter().enumerate() {
            let ty = self.half_height_at(d);
            let tx = ty * self.aspect;
            for (j, (sx, sy)) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)]
                .into_iter()
                .enumerate()
            {
                let p = Vec3::new(sx * tx, sy * ty, -d);
                out[i * 4 + j] = world_from_view.transform_point3(p);
            }
        }
        out
    }

    /// The 6 faces as polygons (world space), each counter-clockwise seen from outside.
    fn faces(&self) -> [[Vec3; 4]; 6] {
        let c = self.corners();
        [
            [c[0], c[2], c[3], c[1]], // near
            [c[4], c[5], c[7], c[6]], // far
            [c[0], c[4], c[6], c[2]], // left
            [c[1], c[3], c[7], c[5]], // right
            [c[0], c[1], c[5], c[4]], // bottom
            [c[2], c[6], c[7], c[3]], // top
        ]
    }
}

/// A half-space n·p + d ≥ 0.
#[derive(Clone, Copy, Debug)]
struct Plane {
    n: Vec3,
    d: f32,
}

impl Plane {
    fn dist(&self, p: Vec3) -> f32 {
        self.n.dot(p) + self.d
    }
}

fn clip_polygon(poly: &[Vec3], plane: Plane) -> Vec<Vec3> {
    let mut out = Vec::with_capacity(poly.len() + 2);
    for i in 0..poly.len() {
        let a = poly[i];
        let b = poly[(i + 1) % poly.len()];
        let (da, db) = (plane.dist(a), plane.dist(b));
        if da >= 0.0 {
            out.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            let t = da / (da - db);
            out.push(a + (b - a) * t);
        }
    }
    out
}

fn box_planes(b: &Aabb) -> [Plane; 6] {
    [
        Plane {
            n: Vec3::X,
            d: -b.min.x,
        },
        Plane {
            n: -Vec3::X,
            d: b.max.x,
        },
        Plane {
            n: Vec3::Y,
            d: -b.min.y,
        },
        Plane {
            n: -Vec3::Y,
            d: b.max.y,
        },
        Plane {
            n: Vec3::Z,
            d: -b.min.z,
        },
        Plane {
            n: -Vec3::Z,
            d: b.max.z,
        },
    ]
}

fn box_faces(b: &Aabb) -> [[Vec3; 4]; 6] {
    let c = b.corners();
    [
        [c[0], c[2], c[6], c[4]],
        [c[1], c[5], c[7], c[3]],
        [c[0], c[4], c[5], c[1]],
        [c[2], c[3], c[7], c[6]],
        [c[0], c[1], c[3], c[2]],
        [c[4], c[6], c[7], c[5]],
    ]
}

/// The vertices of (camera frustum ∩ box): every face of each solid clipped by the other.
/// Empty when they do not meet.
pub fn frustum_box_intersection(f: &CameraFrustum, b: &Aabb) -> Vec<Vec3> {
    if b.is_empty() {
        return Vec::new();
    }
    let faces = f.faces();
    let centre = f.corners().iter().copied().sum::<Vec3>() / 8.0;
    let fplanes: Vec<Plane> = faces
        .iter()
        .map(|q| {
            let mut n = (q[1] - q[0]).cross(q[2] - q[0]).normalize_or_zero();
            let mut d = -n.dot(q[0]);
            if n.dot(centre) + d < 0.0 {
                n = -n;
                d = -d;
            }
            Plane { n, d }
        })
        .collect();
    let mut pts = Vec::new();
    for face in faces.iter() {
        let mut poly = face.to_vec();
        for p in box_planes(b) {
            poly = clip_polygon(&poly, p);
        }
        pts.extend(poly);
    }
    for face in box_faces(b).iter() {
        let mut poly = face.to_vec();
        for p in &fplanes {
            poly = clip_polygon(&poly, *p);
        }
        pts.extend(poly);
    }
    pts
}

/// What a fitted directional-light projection needs.
#[derive(Clone, Copy, Debug)]
pub struct DirectionalFitInput {
    /// Direction the light travels (from the light into the scene).
    pub direction: Vec3,
    /// Bounds of everything that can cast or receive.
    pub scene_bounds: Aabb,
    /// The camera; `None` fits the whole scene.
    pub camera: Option<CameraFrustum>,
    /// More receivers the fit covers with `camera`'s, as a box in the light's view space: where
    /// the frusta of a batch's views meet the scene ([`batch_receivers`]: the views of a batch
    /// sharing one map); ignored without `camera` and by the sphere fit.
    pub also: Option<Aabb>,
    /// Shadow-map size in texels.
    pub map_size: u32,
    /// Quantise the extent and snap the origin to whole texels.
    pub snap: bool,
    /// Cover the bounding sphere of the camera's frustum (within the scene) instead of the
    /// receivers it sees: a size that does not change as the camera moves or turns.
    pub sphere: bool,
    /// With `snap`, steps per doubling of the extent's geometric ladder (8: 2^(1/8) apart).
    pub extent_steps: u32,
    /// With `snap`, the extent the previous frame used (a camera in motion): kept while it
    /// covers what this frame needs at most one doubling too coarse, else stepped from by whole
    /// doublings ([`held_extent`]).
    pub hold: Option<f32>,
}

/// The extent a frame in motion uses when the previous one used `held` and this one needs
/// `need`: `held` while need ≤ held ≤ 2·need, else the nearest held·2^k at least `need` (k may be
/// negative), so the size changes once per doubling of the need, in either direction.
pub fn held_extent(held: f32, need: f32) -> f32 {
    if !(held.is_finite() && held > 0.0 && need.is_finite() && need > 0.0) {
        return need;
    }
    if held >= need && held <= 2.0 * need {
        return held;
    }
    held * (need / held).log2().ceil().exp2()
}

/// What a range bound held in motion becomes when this frame needs `need`: `held` while it
/// covers the need, else widened by whole doublings (`held`·2^k, k ≥ 1) until it does. It never
/// narrows: a camera in motion keeps its cascade splits until the receivers leave them.
pub fn widened(held: f32, need: f32) -> f32 {
    if !(held.is_finite() && held > 0.0 && need.is_finite() && need > 0.0) {
        return need;
    }
    if held >= need {
        return held;
    }
    held * (need / held).log2().ceil().exp2()
}

/// A fitted directional-light projection.
#[derive(Clone, Copy, Debug)]
pub struct DirectionalFit {
    /// World → light view (rotation only: the light space origin is the world origin).
    pub light_view_from_world: Mat4,
    /// World → light clip space (reversed-z orthographic).
    pub light_clip_from_world: Mat4,
    /// Light-space box covered: x/y extent and z from far (min) to near (max).
    pub light_box: Aabb,
    /// World size of one shadow texel.
    pub texel_world: f32,
}

/// The `n` + 1 view depths bounding `n` cascades between `near` and `far`: the practical split
/// scheme (Zhang et al. 2006), a blend of logarithmic and uniform splits weighted by `lambda` (1 =
/// logarithmic: equal texel density ratio per cascade; 0 = uniform).
pub fn cascade_splits(near: f32, far: f32, n: usize, lambda: f32) -> Vec<f32> {
    let n = n.max(1);
    let near = near.max(1e-6);
    let far = far.max(near * 1.0001);
    (0..=n)
        .map(|i| {
            let t = i as f32 / n as f32;
            let log = near * (far / near).powf(t);
            let uniform = near + (far - near) * t;
            if i == 0 {
                near
            } else if i == n {
                far
            } else {
                lambda * log + (1.0 - lambda) * uniform
            }
        })
        .collect()
}

/// World → light view rotation for a light travelling along `direction`.
pub fn light_view_rotation(direction: Vec3) -> Mat4 {
    let d = direction.try_normalize().unwrap_or(-Vec3::Y);
    let up = if d.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
    Mat4::look_to_rh(Vec3::ZERO, d, up)
}

/// Quantises `x > 0` up to the next step of a geometric ladder with `per_octave` steps per
/// doubling (at least 1).
pub fn quantize_extent(x: f32, per_octave: u32) -> f32 {
    let k = per_octave.max(1) as f32;
    let steps = (x.log2() * k).ceil();
    (steps / k).exp2()
}

/// The bounding sphere of the slice of `frustum` between its `near` and `far`: its centre's view
/// depth and its radius. Both depend only on the slice's near and far distances and the
/// frustum's shape (field of view or orthographic size, aspect), not on where the camera is or
/// where it looks.
pub fn slice_sphere(frustum: &CameraFrustum) -> (f32, f32) {
    let (near, far) = (frustum.near, frustum.far);
    // Squared half-diagonals of the near and far cross-sections.
    let s2 = 1.0 + frustum.aspect * frustum.aspect;
    let hn2 = frustum.half_height_at(near).powi(2) * s2;
    let hf2 = frustum.half_height_at(far).powi(2) * s2;
    // Equidistant from the near and far corners, or on the far plane when that is nearer.
    let z = if far > near {
        ((far * far - near * near + hf2 - hn2) / (2.0 * (far - near))).clamp(near, far)
    } else {
        near
    };
    let r = ((z - near).powi(2) + hn2)
        .max((far - z).powi(2) + hf2)
        .sqrt();
    (z, r)
}

/// The sphere fit's square in light space (side, centre x, centre y): it covers the bounding
/// sphere of the camera's frustum slice, so its side does not change as the camera moves or turns
/// (only with its depth range, field of view and aspect); where the scene is narrower than that
/// side along an axis the square is centred on the scene there, else it follows the sphere within
/// the scene's bounds. A fit that hugged the visible receivers would change size every frame the
/// camera moves, and every change of texel size re-rasterises every shadow edge (shimmer).
fn sphere_square(
    c: &CameraFrustum,
    view: &Mat4,
    scene_l: &Aabb,
    min_extent: f32,
) -> (f32, f32, f32) {
    let (z, r) = slice_sphere(c);
    let world_from_view = c.view_from_world.inverse();
    let centre = view.transform_point3(world_from_view.transform_point3(Vec3::new(0.0, 0.0, -z)));
    let (sw, sh) = (scene_l.max.x - scene_l.min.x, scene_l.max.y - scene_l.min.y);
    let side = (2.0 * r).min(sw.max(sh)).max(min_extent);
    let place = |lo: f32, hi: f32, at: f32| {
        if hi - lo <= side {
            0.5 * (lo + hi)
        } else {
            at.clamp(lo + 0.5 * side, hi - 0.5 * side)
        }
    };
    (
        side,
        place(scene_l.min.x, scene_l.max.x, centre.x),
        place(scene_l.min.y, scene_l.max.y, centre.y),
    )
}

/// The receivers' box in light view space (`view`): where the camera's frustum (and the batch's)
/// meets `scene`, within the scene's light-space box `scene_l`; that box itself without a camera
/// or where they do not meet.
fn receiver_box(input: &DirectionalFitInput, view: &Mat4, scene: &Aabb, scene_l: &Aabb) -> Aabb {
    let (seen, any) = match &input.camera {
        Some(c) => {
            let own = frustum_box_intersection(c, scene);
            let also = input.also.unwrap_or(Aabb::EMPTY);
            let seen = Aabb::from_points(own.iter().map(|p| view.transform_point3(*p)));
            (seen.union(&also), !own.is_empty() || !also.is_empty())
        }
        None => (Aabb::EMPTY, false),
    };
    let recv = if any {
        seen.intersection(scene_l)
    } else {
        *scene_l
    };
    if recv.is_empty() {
        *scene_l
    } else {
        recv
    }
}

/// The box a fit takes the scene as: its bounds, or ±1 for an empty scene.
fn fitted_scene(bounds: &Aabb) -> Aabb {
    if bounds.is_empty() {
        Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0))
    } else {
        *bounds
    }
}

/// Where `frusta` meet the scene of `scene_bounds`, as a box in the view space of a light
/// travelling along `direction`: [`DirectionalFitInput::also`] for a batch of views sharing
/// one map. It depends on neither the view nor the map's size, so a batch finds it once per
/// light rather than once per view (each finding clips every frustum of the batch).
pub fn batch_receivers(frusta: &[CameraFrustum], scene_bounds: &Aabb, direction: Vec3) -> Aabb {
    let view = light_view_rotation(direction);
    let scene = fitted_scene(scene_bounds);
    Aabb::from_points(
        frusta
            .iter()
            .flat_map(|c| frustum_box_intersection(c, &scene))
            .map(|p| view.transform_point3(p)),
    )
}

/// Fits an orthographic light projection (see the module documentation).
pub fn fit_directional(input: &DirectionalFitInput) -> DirectionalFit {
    let view = light_view_rotation(input.direction);
    let scene = fitted_scene(&input.scene_bounds);
    let scene_l = scene.transformed(&view);
    let recv = receiver_box(input, &view, &scene, &scene_l);
    let size = input.map_size.max(1) as f32;
    // Guard against a degenerate (flat or point) receiver set.
    let min_extent = (scene.diagonal() * 1e-4).max(1e-4);
    let (raw, cx, cy) = match (&input.camera, input.sphere) {
        (Some(c), true) => sphere_square(c, &view, &scene_l, min_extent),
        _ => (
            (recv.max.x - recv.min.x)
                .max(recv.max.y - recv.min.y)
                .max(min_extent),
            0.5 * (recv.min.x + recv.max.x),
            0.5 * (recv.min.y + recv.max.y),
        ),
    };
    // z: from the farthest receiver to the caster nearest the light (light looks down −z).
    let z_far = recv.min.z;
    let z_near = scene_l.max.z;
    let (lo_x, lo_y, extent, texel, mut zf, mut zn);
    if input.snap {
        let need = raw * (1.0 + 4.0 / size);
        extent = match input.hold {
            Some(h) => held_extent(h, need),
            None => quantize_extent(need, input.extent_steps),
        };
        texel = extent / size;
        lo_x = ((cx - 0.5 * extent) / texel).floor() * texel;
        lo_y = ((cy - 0.5 * extent) / texel).floor() * texel;
        zf = ((z_far / texel).floor() - 2.0) * texel;
        zn = ((z_near / texel).ceil() + 2.0) * texel;
        // Depth on a lattice that holds still: the range on the extent's ladder, the near plane
        // on a multiple of a 16-bit step of it, so a D16 map's stored depths (multiples of that
        // step from the near plane) round the same way from frame to frame while the range
        // stays on its rung.
        let range = quantize_extent(zn - zf, input.extent_steps);
        let step = range / 65535.0;
        zn = (zn / step).ceil() * step;
        zf = zn - range;
    } else {
        extent = raw;
        texel = extent / size;
        lo_x = cx - 0.5 * extent;
        lo_y = cy - 0.5 * extent;
        zf = z_far - 2.0 * texel;
        zn = z_near + 2.0 * texel;
    }
    if zn - zf < texel {
        zn += texel;
        zf -= texel;
    }
    // View space looks down −z: near distance = −zn, far distance = −zf.
    let proj = orthographic_reversed(lo_x, lo_x + extent, lo_y, lo_y + extent, -zn, -zf);
    DirectionalFit {
        light_view_from_world: view,
        light_clip_from_world: proj * view,
        light_box: Aabb::new(
            Vec3::new(lo_x, lo_y, zf),
            Vec3::new(lo_x + extent, lo_y + extent, zn),
        ),
        texel_world: texel,
    }
}

/// A spot light's shadow projection: reversed-z infinite perspective from `position` along
/// `direction`, field of view the outer cone plus a margin. Returns (clip_from_world, tan of half
/// fov): a texel at distance d is `2 * d * tan_half / map_size` wide.
pub fn fit_spot(
    position: Vec3,
    direction: Vec3,
    outer_cone: f32,
    scene_bounds: &Aabb,
) -> (Mat4, f32) {
    let d = direction.try_normalize().unwrap_or(-Vec3::Y);
    let up = if d.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
    let view = Mat4::look_to_rh(position, d, up);
    let half = (outer_cone.clamp(0.01, 1.45) * 1.05).min(1.5);
    let near = spot_near(scene_bounds);
    let proj = perspective_infinite_reversed(2.0 * half, 1.0, near);
    (proj * view, half.tan())
}

/// The six cube-face views of a point light at `position` (faces +x, −x, +y, −y, +z, −z, the
/// order the camera pass picks them in by the major axis), each reaching `margin_texels` of a
/// `size`² layer past 90° so that a lookup's filter near a face's edge stays on that face;
/// returns the views and the tangent of their half angle.
pub fn fit_point_faces(
    position: Vec3,
    scene_bounds: &Aabb,
    size: u32,
    margin_texels: f32,
) -> ([Mat4; 6], f32) {
    // A point on the face's edge (at 45°) projects to 1/t of the half-width: t = 1/(1 − 2m/size)
    // leaves m texels beyond it. At most a quarter of the face.
    let m = (2.0 * margin_texels.max(0.0) / size.max(1) as f32).min(0.25);
    let tan_half = 1.0 / (1.0 - m);
    let proj = perspective_infinite_reversed(2.0 * tan_half.atan(), 1.0, spot_near(scene_bounds));
    let faces = [
        (Vec3::X, Vec3::Y),
        (Vec3::NEG_X, Vec3::Y),
        (Vec3::Y, Vec3::Z),
        (Vec3::NEG_Y, Vec3::Z),
        (Vec3::Z, Vec3::Y),
        (Vec3::NEG_Z, Vec3::Y),
    ];
    (
        faces.map(|(d, up)| proj * Mat4::look_to_rh(position, d, up)),
        tan_half,
    )
}

/// Near-plane distance of a spot light's shadow projection over `scene_bounds`.
pub fn spot_near(scene_bounds: &Aabb) -> f32 {
    (scene_bounds.diagonal() * 1e-3).max(1e-3)
}

/// Light-space clip position of `p` (after the divide).
pub fn project(m: &Mat4, p: Vec3) -> Vec3 {
    let c = *m * Vec4::new(p.x, p.y, p.z, 1.0);
    c.truncate() / c.w
}

#[cfg(test)]
mod tests;
