//! What the viewer prints for a click: the surface under the cursor (node, mesh, primitive,
//! material, triangle, position, normal) and, per light, the exact ray-cast verdict next to the
//! GPU's (the shadow-visibility view read at that pixel for the shadow-mapped light).

use umbra::plan::FramePlan;
use umbra::scene::{LightKind, Scene};
use umbra_lab::reference::Pick;

fn named(kind: &str, i: usize, name: &str) -> String {
    if name.is_empty() {
        format!("{kind} {i}")
    } else {
        format!("{kind} {i} '{name}'")
    }
}

/// The report for `pick` in `scene` under `plan` (whose lights it names); `gpu_visibility` is
/// the GPU's visibility of the plan's shadowed light at the picked pixel, if it was read.
pub fn describe(
    scene: &Scene,
    plan: &FramePlan,
    pixel: (f32, f32),
    pick: Option<&Pick>,
    gpu_visibility: Option<f32>,
) -> String {
    let Some(p) = pick else {
        return format!(
            "pick: pixel ({:.0}, {:.0}): nothing (background)",
            pixel.0, pixel.1
        );
    };
    let inst = &scene.instances[p.instance];
    let node = match inst.node {
        Some(n) => named(
            "node",
            n,
            scene.node_names.get(n).map_or("", |s| s.as_str()),
        ),
        None => format!("instance {} (no glTF node)", p.instance),
    };
    let mesh = named("mesh", p.mesh, &scene.meshes[p.mesh].name);
    let material = named(
        "material",
        p.material,
        scene
            .materials
            .get(p.material)
            .map_or("", |m| m.name.as_str()),
    );
    let mut out = format!(
        "pick: pixel ({:.0}, {:.0}): {node} · {mesh} · primitive {} · {material} · triangle {}\n  \
         position ({:.4}, {:.4}, {:.4}) · normal ({:.3}, {:.3}, {:.3}) · {:.4} from the eye",
        pixel.0,
        pixel.1,
        p.primitive,
        p.triangle,
        p.position.x,
        p.position.y,
        p.position.z,
        p.normal.x,
        p.normal.y,
        p.normal.z,
        p.distance
    );
    for (i, (l, &exact)) in plan.lights.iter().zip(&p.lights_visible).enumerate() {
        let kind = match l.kind {
            LightKind::Directional => "directional",
            LightKind::Point => "point",
            LightKind::Spot { .. } => "spot",
        };
        let verdict = |lit: bool| if lit { "lit" } else { "shadowed" };
        let gpu = if plan.is_shadowed(i) && plan.shadow_light != Some(i) {
            "GPU shadows it too (the shadow view reads the shown light only)".into()
        } else if plan.is_shadowed(i) {
            match gpu_visibility {
                Some(v) => format!(
                    "GPU {} (visibility {v:.2}){}",
                    verdict(v >= 0.5),
                    if (v >= 0.5) == exact {
                        ""
                    } else {
                        " ← disagrees"
                    }
                ),
                None => "GPU not read".into(),
            }
        } else {
            "GPU casts no shadow for it (facing only)".into()
        };
        out += &format!("\n  light {i} ({kind}): exact {} · {gpu}", verdict(exact));
    }
    out
}
