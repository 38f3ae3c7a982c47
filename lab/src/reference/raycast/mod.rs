//! Exact shadow visibility and a Blinn-Phong reference image by ray casting, for the same view
//! (same pixel centres, lights and material constants) as a GPU frame.

mod rays;
mod surface;

use crate::reference::bvh::{Bvh, Hit};
use glam::{Mat3, Mat4, Vec3, Vec4};
use rayon::prelude::*;
use rays::{face_viewer, light_at, primary_ray};
use surface::{srgb_encode, surface_inputs};
use umbra::math::interp::perturb_normal;
use umbra::math::ray::{coordinate_magnitudes, Ray};
use umbra::math::Aabb;
use umbra::plan::{Ambient, FramePlan};
use umbra::scene::{blinn_phong_params, shade_blinn_phong, Scene};

/// Where a world triangle came from.
#[derive(Clone, Copy, Debug)]
struct TriRef {
    instance: u32,
    mesh: u32,
    primitive: u32,
    /// Index of the triangle's first index in the primitive.
    first: u32,
    /// Its draw's coordinate magnitudes (`umbra::math::ray::coordinate_magnitudes`): how far
    /// shadow rays leaving it start off it, as on the GPU.
    magnitudes: Vec3,
}

/// A scene prepared for ray casting: world-space triangles in a BVH, plus what shading needs.
/// Like the renderer, it works relative to [`Scene::render_origin`] (rays, hits and the plans it
/// reads are in those coordinates).
pub struct ReferenceScene<'a> {
    scene: &'a Scene,
    /// Each instance's model → world relative to `origin`.
    matrices: Vec<Mat4>,
    /// The point its coordinates are relative to.
    pub origin: Vec3,
    /// The hierarchy.
    pub bvh: Bvh,
    refs: Vec<TriRef>,
    normal_mats: Vec<Mat3>,
    srgb_lut: [f32; 256],
}

/// The reference result for one view.
pub struct ReferenceFrame {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Per pixel: None when no surface is hit; else exact visibility of the shadowed light
    /// (facing and unoccluded → true).
    pub visibility: Vec<Option<bool>>,
    /// Per pixel: None when no surface is hit; else the fraction of the shadowed light's
    /// emitter visible (`AREA_SAMPLES` shadow rays over it when it has a size, 0 or 1 for a
    /// punctual light; 0 where the surface faces away): ground truth for soft shadows.
    pub coverage: Vec<Option<f32>>,
    /// Per pixel: distance along the primary ray (∞ for none).
    pub distance: Vec<f32>,
    /// The reference image (sRGB), exact hard shadows.
    pub image: image::RgbaImage,
    /// Per pixel: the surface seen is curved (its interpolated normal leaves the flat face's by
    /// more than 1°); false for flat faces and for the background.
    pub curved: Vec<bool>,
    /// Per pixel: the cosine between the surface's interpolated normal (facing the viewer) and
    /// the direction to the shadowed light, the n·l that decides whether it faces the light; 1
    /// where no surface is hit or no light is shadowed.
    pub incidence: Vec<f32>,
    /// Per pixel: another face lies where the surface seen lies (within 10⁻⁶ of its distance)
    /// and the shadowed light judges it otherwise, as when a card is modelled twice with opposite
    /// windings and normals. Which of the two a depth test keeps is a tie, so such pixels are
    /// not judged (`compare`'s `coincident_surfaces`).
    pub coincident: Vec<bool>,
}

/// One reference pixel: (centre visibility, visible fraction) of the shadowed light where a
/// surface is hit, distance, colour, curved, incidence, coincident.
type PixelResult = (Option<(bool, f32)>, f32, [u8; 4], bool, f32, bool);

impl ReferenceFrame {
    /// The shadowed light's visible fraction as the GPU's shadow view writes visibility: grey
    /// bytes of fraction × 255 (the view writes linear values to an sRGB target, so the byte
    /// is the value), the clear colour where no surface is hit.
    pub fn coverage_image(&self) -> image::RgbaImage {
        let c = umbra::plan::CLEAR_COLOR;
        let background = [srgb_encode(c[0]), srgb_encode(c[1]), srgb_encode(c[2]), 255];
        image::RgbaImage::from_fn(self.width, self.height, |x, y| {
            match self.coverage[(y * self.width + x) as usize] {
                None => image::Rgba(background),
                Some(v) => {
                    let b = (v.clamp(0.0, 1.0) * 255.0).round() as u8;
                    image::Rgba([b, b, b, 255])
                }
            }
        })
    }
}

/// cos 1°: a surface whose interpolated normal leaves the face normal by more is curved.
const CURVED_COS: f32 = 0.999_847_7;
/// Shadow rays a light with a size casts per shaded point: the emitter is sampled on a fixed
/// area-uniform golden-angle spiral over its disk (the sun's disk of directions; a sphere light's
/// disk facing the point).
pub const AREA_SAMPLES: usize = 128;
/// Most blended surfaces one primary ray composites (deeper ones are taken as opaque).
const MAX_BLEND_LAYERS: u32 = 8;

/// What a probe ray found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Probe {
    /// World position of the hit.
    pub position: Vec3,
    /// Geometric normal, facing the camera.
    pub normal: Vec3,
    /// How far its shadow rays start off it (`umbra::math::ray::ray_offset`).
    pub offset: f32,
    /// Distance along the ray.
    pub distance: f32,
    /// Exact visibility of the shadowed light (facing it and unoccluded).
    pub visible: bool,
    /// Another face lies at the same distance and the light judges it otherwise: a depth tie
    /// (twin cards), left out of judgements as `compare` leaves it
    /// ([`ReferenceFrame::coincident`]).
    pub coincident: bool,
}

/// What a click on the image hits (`ReferenceScene::pick`).
#[derive(Clone, Debug, PartialEq)]
pub struct Pick {
    /// Index into `Scene::instances` (its `node` names the glTF node).
    pub instance: usize,
    /// Index into `Scene::meshes`.
    pub mesh: usize,
    /// Index into the mesh's primitives (as loaded).
    pub primitive: usize,
    /// Index into `Scene::materials`.
    pub material: usize,
    /// Triangle index within the primitive (its indices `3t..3t+3`).
    pub triangle: usize,
    /// World position of the hit (the scene's own coordinates).
    pub position: Vec3,
    /// Geometric normal, facing the camera.
    pub normal: Vec3,
    /// Distance from the eye.
    pub distance: f32,
    /// Per light of the plan: exactly lit there (facing it and unoccluded).
    pub lights_visible: Vec<bool>,
}

impl<'a> ReferenceScene<'a> {
    /// Collects world-space triangles of every instance and builds the BVH.
    pub fn new(scene: &'a Scene) -> Self {
        let mut tris = Vec::new();
        let mut refs = Vec::new();
        let mut normal_mats = Vec::new();
        let origin = scene.render_origin();
        let matrices: Vec<Mat4> = scene
            .instances
            .iter()
            .map(|i| umbra::scene::rebased(i.world_from_model, origin))
            .collect();
        for (ii, inst) in scene.instances.iter().enumerate() {
            let world_from_model = matrices[ii];
            let m3 = Mat3::from_mat4(world_from_model);
            normal_mats.push(if m3.determinant().abs() > 1e-30 {
                m3.inverse().transpose()
            } else {
                m3
            });
            for (pi, p) in scene.meshes[inst.mesh].primitives.iter().enumerate() {
                let world: Vec<Vec3> = p
                    .positions
                    .iter()
                    .map(|v| world_from_model.transform_point3(*v))
                    .collect();
                let bounds = Aabb::from_points(world.iter().copied());
                let magnitudes = coordinate_magnitudes(&bounds, &world_from_model);
                for (k, t) in p.indices.chunks_exact(3).enumerate() {
                    tris.push([
                        world[t[0] as usize],
                        world[t[1] as usize],
                        world[t[2] as usize],
                    ]);
                    refs.push(TriRef {
                        instance: ii as u32,
                        mesh: inst.mesh as u32,
                        primitive: pi as u32,
                        first: (k * 3) as u32,
                        magnitudes,
                    });
                }
            }
        }
        let bvh = Bvh::build(&tris);
        let mut srgb_lut = [0.0; 256];
        for (i, v) in srgb_lut.iter_mut().enumerate() {
            *v = umbra::math::tonemap::srgb_to_linear(i as f32 / 255.0);
        }
        Self {
            scene,
            matrices,
            origin,
            bvh,
            refs,
            normal_mats,
            srgb_lut,
        }
    }

    /// What lies under image position (`x`, `y`) (pixel units, centres at +0.5) of `plan`'s
    /// camera: the surface the primary ray hits first, with each of the plan's lights' exact
    /// verdict there (facing it, and unoccluded whether or not the GPU shadows that light).
    pub fn pick(&self, plan: &FramePlan, x: f32, y: f32, width: u32, height: u32) -> Option<Pick> {
        debug_assert_eq!(
            plan.origin, self.origin,
            "plan and reference share an origin"
        );
        let inv = plan.clip_from_world.inverse();
        let ray = primary_ray(plan, &inv, x, y, width, height);
        let h = self.intersect(&ray)?;
        let r = self.refs[h.triangle as usize];
        let prim = &self.scene.meshes[r.mesh as usize].primitives[r.primitive as usize];
        let rc = self.receiver(&ray, &h);
        let lights = plan
            .lights
            .iter()
            .map(|l| {
                let (dir, dist, _) = light_at(l, rc.p);
                rc.n_geo.dot(dir) > 0.0 && !self.occluded((rc.p, rc.offset), rc.ng, dir, dist)
            })
            .collect();
        Some(Pick {
            instance: r.instance as usize,
            mesh: r.mesh as usize,
            primitive: r.primitive as usize,
            material: prim.material,
            triangle: r.first as usize / 3,
            position: rc.p + self.origin,
            normal: rc.ng,
            distance: h.t,
            lights_visible: lights,
        })
    }

    /// Exact visibility at chosen pixel centres of `plan`'s camera (for sparse probes: the error
    /// budget's prediction). `None` where the ray hits nothing.
    pub fn probe(
        &self,
        plan: &FramePlan,
        pixels: &[(f32, f32)],
        width: u32,
        height: u32,
    ) -> Vec<Option<Probe>> {
        debug_assert_eq!(
            plan.origin, self.origin,
            "plan and reference share an origin"
        );
        let inv = plan.clip_from_world.inverse();
        pixels
            .par_iter()
            .map(|&(x, y)| {
                let ray = primary_ray(plan, &inv, x, y, width, height);
                // The receiver judged, as in `render`: blended texels below the cutoff let the
                // ray through.
                let h = self
                    .bvh
                    .intersect_where(&ray, 0.0, f32::INFINITY, &|h: &Hit| self.stops(h, true))?;
                // The same receiver, flips and facing test as `render`, and its tie rule.
                let r = self.receiver(&ray, &h);
                let visible = plan
                    .shadow_light
                    .is_none_or(|i| self.centre_visible(plan, i, &r));
                Some(Probe {
                    position: r.p,
                    normal: r.ng,
                    offset: r.offset,
                    distance: h.t,
                    visible,
                    coincident: self.coincident(plan, &ray, &h, visible),
                })
            })
            .collect()
    }

    /// Casts one primary ray per pixel centre of `plan`'s camera and shades the hits; the
    /// background where nothing is hit is `plan`'s ([`FramePlan::background_along`]).
    pub fn render(
        &self,
        plan: &FramePlan,
        width: u32,
        height: u32,
        ambient: Ambient,
    ) -> ReferenceFrame {
        debug_assert_eq!(
            plan.origin, self.origin,
            "plan and reference share an origin"
        );
        let inv = plan.clip_from_world.inverse();
        let n = (width * height) as usize;
        let results: Vec<PixelResult> = (0..n)
            .into_par_iter()
            .map(|i| {
                let (x, y) = (
                    (i as u32 % width) as f32 + 0.5,
                    (i as u32 / width) as f32 + 0.5,
                );
                self.pixel(plan, primary_ray(plan, &inv, x, y, width, height), ambient)
            })
            .collect();
        let mut image = image::RgbaImage::new(width, height);
        for (i, r) in results.iter().enumerate() {
            image.put_pixel(i as u32 % width, i as u32 / width, image::Rgba(r.2));
        }
        ReferenceFrame {
            width,
            height,
            visibility: results.iter().map(|r| r.0.map(|v| v.0)).collect(),
            coverage: results.iter().map(|r| r.0.map(|v| v.1)).collect(),
            distance: results.iter().map(|r| r.1).collect(),
            image,
            curved: results.iter().map(|r| r.3).collect(),
            incidence: results.iter().map(|r| r.4).collect(),
            coincident: results.iter().map(|r| r.5).collect(),
        }
    }

    /// One pixel of [`ReferenceScene::render`] along its primary ray `ray`: the shown light's
    /// verdict and emitter fraction at the receiver judged, its distance, the colour, whether it
    /// is curved, its incidence and whether it is a depth tie.
    fn pixel(&self, plan: &FramePlan, ray: Ray, ambient: Ambient) -> PixelResult {
        let encode = |c: Vec3| [srgb_encode(c.x), srgb_encode(c.y), srgb_encode(c.z), 255];
        match self.intersect(&ray) {
            None => (
                None,
                f32::INFINITY,
                encode(plan.background_along(ray.dir)),
                false,
                1.0,
                false,
            ),
            Some(h) => {
                let (vis, cover, rgb) = self.shade(plan, &ray, &h, ambient);
                let rgb = plan.display_surface(rgb, self.unlit(&h));
                let rgb = self.blend_behind(plan, &ray, &h, rgb, ambient, 0);
                // The receiver judged: the first surface that would stop a shadow ray.
                let (h, vis, cover) = if self.stops(&h, true) {
                    (h, vis, cover)
                } else {
                    match self.receiver_beyond(&ray, &h) {
                        None => return (None, f32::INFINITY, encode(rgb), false, 1.0, false),
                        Some(r) => {
                            let (vis, cover, _) = self.shade(plan, &ray, &r, ambient);
                            (r, vis, cover)
                        }
                    }
                };
                let r = self.receiver(&ray, &h);
                let incidence = plan.shadow_light.map_or(1.0, |i| {
                    r.n_geo.dot(light_at(&plan.lights[i], ray.at(h.t)).0)
                });
                let coincident = self.coincident(plan, &ray, &h, vis);
                (
                    Some((vis, cover)),
                    h.t,
                    encode(rgb),
                    r.ng.dot(r.n_geo).abs() < CURVED_COS,
                    incidence,
                    coincident,
                )
            }
        }
    }

    /// The shown light's centre visibility and emitter fraction, and the lit colour.
    fn shade(&self, plan: &FramePlan, ray: &Ray, h: &Hit, ambient: Ambient) -> (bool, f32, Vec3) {
        let r = self.refs[h.triangle as usize];
        let prim = &self.scene.meshes[r.mesh as usize].primitives[r.primitive as usize];
        let idx = [
            prim.indices[r.first as usize] as usize,
            prim.indices[r.first as usize + 1] as usize,
            prim.indices[r.first as usize + 2] as usize,
        ];
        let w = Vec3::new(1.0 - h.u - h.v, h.u, h.v);
        let m3 = Mat3::from_mat4(self.matrices[r.instance as usize]);
        // The receiver's normals turned to the viewer; the normal map perturbs the stored one.
        let rc = self.receiver(ray, h);
        let (p, offset, ng) = (rc.p, rc.offset, rc.ng);
        let n_geo = if rc.flipped { -rc.n_geo } else { rc.n_geo };
        let (uv, vertex_color) = surface_inputs(prim, r.first as usize, h);
        let mat = &self.scene.materials[prim.material.min(self.scene.materials.len() - 1)];
        let base = mat.base_color
            * vertex_color
            * self.sample(mat.base_color_texture, uv, true, Vec4::ONE);
        let mut n = n_geo;
        if mat.normal_texture.is_some() && !prim.tangents.is_empty() {
            let t4 = prim.tangents[idx[0]] * w.x
                + prim.tangents[idx[1]] * w.y
                + prim.tangents[idx[2]] * w.z;
            // A mirroring transform flips the bitangent, as in the vertex shader.
            let det_sign = if m3.determinant() < 0.0 { -1.0 } else { 1.0 };
            let s = self.sample(mat.normal_texture, uv, false, Vec4::new(0.5, 0.5, 1.0, 1.0));
            let tn = s.truncate() * 2.0 - Vec3::ONE;
            let tn = Vec3::new(tn.x * mat.normal_scale, tn.y * mat.normal_scale, tn.z);
            n = perturb_normal(
                n_geo,
                m3 * t4.truncate(),
                prim.tangents[idx[0]].w * det_sign,
                tn,
            );
        }
        // Back faces (seen only on double-sided materials on the GPU) flip like the shader does.
        let n_geo = rc.n_geo;
        if rc.flipped {
            n = -n;
        }
        let mr = self.sample(mat.metallic_roughness_texture, uv, false, Vec4::ONE);
        let bp = blinn_phong_params(base.truncate(), mat.metallic * mr.z, mat.roughness * mr.y);
        let emissive = mat.emissive
            * self
                .sample(mat.emissive_texture, uv, true, Vec4::ONE)
                .truncate();
        let v = -ray.dir;
        let occ = self.sample(mat.occlusion_texture, uv, false, Vec4::ONE).x;
        let occlusion = if mat.occlusion_texture.is_some() {
            1.0 + mat.occlusion_strength * (occ - 1.0)
        } else {
            1.0
        };
        let mut color = bp.ka * ambient.at(n) * occlusion + emissive;
        let (mut shadow_vis, mut shadow_cover) = (true, 1.0);
        for i in 0..plan.lights.len() {
            let (vis, cover, l, radiance) = self.visible(plan, i, (p, offset), ng, n_geo);
            if plan.shadow_light == Some(i) {
                (shadow_vis, shadow_cover) = (vis, cover);
            }
            color += shade_blinn_phong(&bp, n, l, v, radiance, cover);
        }
        if mat.unlit {
            color = base.truncate();
        }
        (shadow_vis, shadow_cover, color)
    }
}
