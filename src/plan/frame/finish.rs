//! The plan finished at birth: after the shadow views, their casters (`FramePlan::plan_casters`),
//! the exact method's choice and the camera's sight are made here, inside `plan_frame`, so
//! nothing fills the plan in after it is made.

use super::FramePlan;
use crate::plan::casters::Viewpoint;
use crate::plan::exact::{
    exact_asked, ExactMode, ExactPlan, HybridPlan, CONTACT_TEXELS, CONTACT_THICKNESS,
};
use crate::plan::input::{PlanScene, PlanTarget};
use crate::plan::reach::ShadowReach;
use crate::plan::settings::ViewMode;
use crate::plan::sight::Sight;
use crate::plan::view::View;
use crate::plan::ShadowMethod;
use crate::scene::LightKind;
use crate::shader_consts::VariantKey;

/// Finishes `plan` for `view` of `scene` into `target`: the casters of its shadow views, the
/// exact method's choice (and its shader bit) and the camera's sight.
pub(super) fn finish(plan: &mut FramePlan, scene: &PlanScene, view: &View, target: &PlanTarget) {
    plan.plan_casters(scene, view.shadow.pcf, view.mode == ViewMode::ShadowMap);
    plan.exact = choose_exact(plan, view, scene, target.aspect, target.exact_capable);
    if plan.exact.is_some() {
        plan.shader_variant |= VariantKey::EXACT;
    }
    plan.sight = sight(plan, view, target.aspect, target.receiver_split);
}

/// The exact pass of a frame planned as `plan` for `view` (relative to the plan's origin) of
/// `scene` at `aspect`, when it applies: exact shadows need one shadowed directional or spot
/// light with one view (or a point light's six); contact shadows a shown shadowed light and
/// hard shadows (they march `CONTACT_TEXELS` of its finest view).
pub(super) fn choose_exact(
    plan: &FramePlan,
    view: &View,
    scene: &PlanScene,
    aspect: f32,
    capable: bool,
) -> Option<ExactPlan> {
    let exact = exact_asked(view, capable);
    let contact = !exact && view.shadow.enabled && view.shadow.contact && capable;
    if !exact && !contact {
        return None;
    }
    let bits = plan.shader_variant;
    let (shown, first) = plan
        .shadow_light
        .and_then(|i| {
            plan.shadow_views
                .iter()
                .position(|v| v.light == i)
                .map(|first| (i, first))
        })
        .filter(|_| plan.shadows_on && bits.contains(VariantKey::SHADOWS))?;
    let mode = exact_mode(plan, scene, shown, first, contact)?;
    let (light, positional) = match plan.light_source(shown) {
        Viewpoint::Eye(p) => (p, true),
        Viewpoint::Along(d) => (d, false),
    };
    let cam = &view.camera;
    let half = cam.half_extent_at(cam.near, aspect);
    let views = plan.shadow_views.len();
    let hybrid =
        (mode == ExactMode::Exact && views == 1 && view.shadow.method == ShadowMethod::Hybrid)
            .then(|| hybrid_plan(plan, first));
    Some(ExactPlan {
        hybrid,
        mode,
        views: plan
            .shadow_views
            .iter()
            .map(|v| v.light_clip_from_world)
            .collect(),
        light,
        positional,
        clip_from_world: plan.clip_from_world,
        eye: (
            plan.camera_position,
            (cam.near * cam.near + half.length_squared()).sqrt(),
        ),
        receivers: (0..scene.receivers.len()).collect(),
        casters: match mode {
            ExactMode::Exact => {
                let mut all: Vec<usize> = plan
                    .shadow_views
                    .iter()
                    .flat_map(|v| v.casters.draws.iter().copied())
                    .collect();
                all.sort_unstable();
                all.dedup();
                all
            }
            ExactMode::Contact { .. } => Vec::new(),
        },
    })
}

/// What the exact pass does for the shown light `shown` (its first view `first`): exact shadows
/// when its views are the frame's, one (a sun's single map, a spot light) or a point light's
/// six faces; contact shadows (`contact`) with hard shadows; else nothing.
fn exact_mode(
    plan: &FramePlan,
    scene: &PlanScene,
    shown: usize,
    first: usize,
    contact: bool,
) -> Option<ExactMode> {
    let only_shown = plan.shadow_views.iter().all(|v| v.light == shown);
    let point = plan.lights[shown].kind == LightKind::Point;
    let views = plan.shadow_views.len();
    match contact {
        false if only_shown && (views == 1 || (point && views == 6)) => Some(ExactMode::Exact),
        true if !plan.shader_variant.contains(VariantKey::SOFT) => {
            let length = CONTACT_TEXELS * plan.shadow_views[first].texel_world;
            Some(ExactMode::Contact {
                length,
                thickness: CONTACT_THICKNESS * length,
                margin: (scene.bounds.diagonal() * 2e-5).max(1e-6),
            })
        }
        _ => None,
    }
}

/// The hybrid method's inputs from the frame's one shadow view, `first`.
fn hybrid_plan(plan: &FramePlan, first: usize) -> HybridPlan {
    let v = &plan.shadow_views[first];
    HybridPlan {
        world_from_clip: v.light_clip_from_world.as_dmat4().inverse().as_mat4(),
        map_size: v.casters.size,
        rect: v.casters.lookup.to_array(),
        texel_world: v.texel_world,
    }
}

/// The sight of `view` planned as `plan` at `aspect`; with `receiver_split`, the reach of a
/// single shadow view.
pub(super) fn sight(plan: &FramePlan, view: &View, aspect: f32, receiver_split: bool) -> Sight {
    let cam = &view.camera;
    let half = cam.half_extent_at(cam.near, aspect);
    let single_view = plan.shadow_views.len() == 1;
    let bits = plan.shader_variant;
    let shadow_reach = (receiver_split
        && view.mode == ViewMode::Lit
        && plan.shadows_on
        && single_view
        && bits.contains(VariantKey::SHADOWS)
        && !bits.contains(VariantKey::MANY_VIEWS))
    .then(|| {
        let sv = &plan.shadow_views[0];
        let apex = match plan.light_source(sv.light) {
            Viewpoint::Eye(p) => Some(p),
            Viewpoint::Along(_) => None,
        };
        ShadowReach::new(
            &sv.light_clip_from_world,
            sv.casters.lookup,
            sv.res as f32,
            view.shadow.normal_offset.abs() + view.shadow.constant_bias.abs(),
            sv.texel_world,
            apex,
        )
    });
    Sight {
        eye: (
            plan.camera_position,
            (cam.near * cam.near + half.length_squared()).sqrt(),
        ),
        viewpoint: if cam.is_orthographic() {
            Viewpoint::Along(cam.forward())
        } else {
            Viewpoint::Eye(plan.camera_position)
        },
        shadow_reach,
    }
}
