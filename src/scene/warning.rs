//! Loader warnings with stable codes and JSON pointers: what `render` prints and `umbra inspect`
//! reports as findings.

/// One repair or unsupported feature met while loading.
#[derive(Clone, Debug, PartialEq)]
pub struct Warning {
    /// Stable code (`FINDING_CODES`).
    pub code: &'static str,
    /// JSON pointer into the file (`/meshes/2/primitives/0`), or empty when it names no object.
    pub pointer: String,
    /// What happened, for people.
    pub message: String,
}

impl std::fmt::Display for Warning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

/// Finding codes: (code, severity, what it means). The loader's warnings and `umbra inspect`'s
/// own findings use these.
pub const FINDING_CODES: &[(&str, &str, &str)] = &[
    (
        "MESH_NORMALS_MISSING",
        "info",
        "a primitive has no NORMAL; umbra computes smooth normals",
    ),
    (
        "MESH_TANGENTS_FAILED",
        "warning",
        "MikkTSpace tangent generation failed; the normal map may be wrong",
    ),
    (
        "MESH_COLORS_IGNORED",
        "warning",
        "COLOR_0 with another count than the vertices is ignored",
    ),
    (
        "MESH_NONFINITE_POSITIONS",
        "warning",
        "triangles with NaN or infinite positions were dropped",
    ),
    ("MESH_DEGENERATE_TRIANGLES", "info", "zero-area triangles"),
    (
        "MESH_NORMALS_NOT_UNIT",
        "warning",
        "stored normals not of unit length were normalised",
    ),
    (
        "MESH_TANGENTS_INVALID",
        "warning",
        "stored tangents with w other than ±1 or xyz not of unit length were repaired",
    ),
    (
        "ACCESSOR_MIN_MAX_MISMATCH",
        "warning",
        "a POSITION accessor's declared min/max differ from its data",
    ),
    (
        "MESH_NO_POSITION",
        "warning",
        "a primitive without POSITION was skipped",
    ),
    (
        "MESH_UNSUPPORTED_MODE",
        "warning",
        "points or lines are not drawn",
    ),
    (
        "NODE_NONFINITE_TRANSFORM",
        "warning",
        "a node with a non-finite transform was skipped",
    ),
    (
        "CAMERA_INVALID",
        "warning",
        "a camera's projection is out of range (a zero or non-finite size or field of view, a far \
         plane not beyond the near one): repaired as the message says",
    ),
    (
        "MATERIAL_ALPHA_BLEND",
        "info",
        "alpha-blended: sorted back to front per draw, casts where alpha >= 0.5",
    ),
    (
        "TEXCOORD_FALLBACK",
        "warning",
        "a texture reads a TEXCOORD set umbra does not load (2 and up), or a TEXCOORD_1 of the \
         wrong count: set 0 is read",
    ),
    (
        "MATERIAL_OCCLUSION_IGNORED",
        "warning",
        "an occlusion texture not packable with metallic-roughness (size, sampler, transform) is ignored",
    ),
    (
        "IMAGE_NOT_LOADED",
        "warning",
        "an image could not be read or decoded; its slots use defaults",
    ),
    (
        "NORMAL_MAP_WITHOUT_UVS",
        "warning",
        "a normal map on a primitive without TEXCOORD_0 is ignored",
    ),
    (
        "EXTENSION_UNSUPPORTED",
        "info",
        "an extension used by the file that umbra ignores",
    ),
    ("SCENE_EMPTY", "warning", "the scene has no mesh instances"),
    (
        "UNUSED_MESH",
        "info",
        "a mesh no node of the rendered scene instances",
    ),
    ("UNUSED_MATERIAL", "info", "a material no primitive uses"),
    ("UNUSED_TEXTURE", "info", "a texture no material uses"),
    (
        "ANIMATION_CHANNEL_INVALID",
        "warning",
        "an animation channel with times not strictly increasing, non-finite keys, an output \
         count that does not match its inputs or accessor types glTF forbids is ignored",
    ),
    (
        "SKIN_INVALID",
        "warning",
        "a skin without joints, with too many, or with inverse bind matrices of the wrong count \
         or non-finite: its meshes are drawn unskinned",
    ),
    (
        "SKIN_WEIGHTS_NOT_NORMALIZED",
        "warning",
        "vertex weights that do not sum to 1 were normalised (a zero sum binds the vertex to the \
         skin's first joint)",
    ),
    (
        "SKIN_JOINT_OUT_OF_RANGE",
        "warning",
        "influences naming joints past the skin's joint count lose their weight",
    ),
    (
        "SKIN_MISSING",
        "warning",
        "a primitive with JOINTS_0 on a node without a skin is drawn as stored",
    ),
    (
        "MORPH_TARGET_INVALID",
        "warning",
        "a morph target with a wrong count or non-finite displacements is ignored",
    ),
];

/// The severity of `code` (`FINDING_CODES`; "warning" for an unknown code).
pub fn severity_of(code: &str) -> &'static str {
    FINDING_CODES
        .iter()
        .find(|c| c.0 == code)
        .map_or("warning", |c| c.1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_are_unique_with_known_severities() {
        for (i, (code, sev, _)) in FINDING_CODES.iter().enumerate() {
            assert!(["info", "warning", "error"].contains(sev), "{code}");
            assert!(
                FINDING_CODES[..i].iter().all(|c| c.0 != *code),
                "{code} listed twice"
            );
        }
        assert_eq!(severity_of("UNUSED_MESH"), "info");
    }
}
