//! Compiles every WGSL file in `shaders/` to SPIR-V with naga, validating it with every check on.
//!
//! A shader error fails the build with `file:line:column: message` followed by naga's annotated
//! source excerpt. For each shader the build also writes reflection constants (binding numbers,
//! descriptor kinds, uniform struct sizes, immediate-block size) so that Rust code never hand-syncs
//! binding numbers: see `src/gpu/shaders.rs`.
//!
//! Shaders are composed from parts: a line `#include "lib/NAME.wgsl"` is replaced by that file
//! (relative to `shaders/`, each part included once per shader), so structs shared by two shaders
//! are written once. Only the top-level `shaders/*.wgsl` files are shaders; errors name the part
//! and its line. Named module-scope constants of a shader (`const VIEW_LIT: u32 = 0u;`) are
//! generated as Rust constants too, so light kinds, view modes and array sizes are never typed on
//! both sides of the boundary.
//!
//! Y convention: SPIR-V is written with `ADJUST_COORDINATE_SPACE`, so shaders work in a Y-up clip
//! space (like WebGPU/OpenGL) and naga negates `position.y` on the way out. Shadow-map UVs are
//! therefore `(x * 0.5 + 0.5, 0.5 - y * 0.5)`.

use std::fmt::Write as _;
use std::path::Path;

fn main() {
    let out_dir = std::env::var("OUT_DIR").expect("OUT_DIR");
    println!("cargo:rerun-if-changed=shaders");
    println!("cargo:rerun-if-changed=shaders/lib");
    let mut entries: Vec<_> = std::fs::read_dir("shaders")
        .expect("shaders/ folder")
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "wgsl"))
        .collect();
    entries.sort();
    let (mut generated, mut consts) = (String::new(), String::new());
    let mut failures = Vec::new();
    for path in &entries {
        println!("cargo:rerun-if-changed={}", path.display());
        match compile(path, &out_dir) {
            Ok((code, c)) => {
                generated.push_str(&code);
                consts.push_str(&c);
            }
            Err(msg) => failures.push(msg),
        }
    }
    if !failures.is_empty() {
        for f in &failures {
            eprintln!("{f}");
        }
        // The first line of each failure is `file:line:col: error`, which cargo prints verbatim.
        panic!("shader compilation failed:\n{}", failures.join("\n"));
    }
    std::fs::write(Path::new(&out_dir).join("shaders.rs"), generated).expect("write shaders.rs");
    std::fs::write(Path::new(&out_dir).join("shader_consts.rs"), consts)
        .expect("write shader_consts.rs");
}

/// A shader's source with its `#include` lines expanded, and for each line of it the file and
/// line it came from.
struct Composed {
    source: String,
    lines: Vec<(String, u32)>,
}

fn compose(path: &Path) -> Result<Composed, String> {
    let mut out = Composed {
        source: String::new(),
        lines: Vec::new(),
    };
    let mut seen = Vec::new();
    expand(path, &mut out, &mut seen)?;
    Ok(out)
}

fn expand(
    path: &Path,
    out: &mut Composed,
    seen: &mut Vec<std::path::PathBuf>,
) -> Result<(), String> {
    let text =
        std::fs::read_to_string(path).map_err(|e| format!("{}:1:1: error: {e}", path.display()))?;
    for (n, line) in text.lines().enumerate() {
        if let Some(rest) = line.trim().strip_prefix("#include ") {
            let name = rest.trim().trim_matches('"');
            let part = Path::new("shaders").join(name);
            if !part.is_file() {
                return Err(format!(
                    "{}:{}:1: error: no shader part {}",
                    path.display(),
                    n + 1,
                    part.display()
                ));
            }
            println!("cargo:rerun-if-changed={}", part.display());
            if !seen.contains(&part) {
                seen.push(part.clone());
                expand(&part, out, seen)?;
            }
            continue;
        }
        out.source.push_str(line);
        out.source.push('\n');
        out.lines.push((path.display().to_string(), n as u32 + 1));
    }
    Ok(())
}

fn location_prefix(path: &Path, composed: &Composed, loc: Option<naga::SourceLocation>) -> String {
    match loc.and_then(|l| {
        Some((
            composed.lines.get(l.line_number.checked_sub(1)? as usize)?,
            l,
        ))
    }) {
        Some(((file, line), l)) => format!("{file}:{line}:{}", l.line_position),
        None => format!("{}:1:1", path.display()),
    }
}

fn compile(path: &Path, out_dir: &str) -> Result<(String, String), String> {
    let composed = compose(path)?;
    let source = composed.source.as_str();
    let file = path.display().to_string();
    let module = naga::front::wgsl::parse_str(source).map_err(|e| {
        format!(
            "{}: error: {}\n{}",
            location_prefix(path, &composed, e.location(source)),
            e.message(),
            e.emit_to_string_with_path(source, &file)
        )
    })?;
    let mut validator = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        // f16 packing (`pack2x16float`: GLSL.std.450 PackHalf2x16, core in Vulkan).
        naga::valid::Capabilities::IMMEDIATES
            | naga::valid::Capabilities::SHADER_FLOAT16_IN_FLOAT32,
    );
    let info = validator.validate(&module).map_err(|e| {
        format!(
            "{}: error: {}\n{}",
            location_prefix(path, &composed, e.location(source)),
            e.as_inner(),
            e.emit_to_string_with_path(source, &file)
        )
    })?;
    // Boolean `override`s specialise the shader: one SPIR-V per combination (bit i of the
    // variant index = the i-th override, in declaration order), since naga's SPIR-V writer has
    // no specialization constants. The driver then drops the dead branches, which matters on
    // llvmpipe: it executes both sides of every branch, uniform or not.
    let stem = path.file_stem().unwrap().to_string_lossy().to_string();
    let overrides: Vec<String> = module
        .overrides
        .iter()
        .map(|(_, o)| o.name.clone().unwrap_or_default())
        .collect();
    if overrides.len() > 11 {
        return Err(format!(
            "{}:1:1: error: at most 11 boolean overrides (one SPIR-V per combination)",
            path.display()
        ));
    }
    let (requires, excludes) = override_rules(path, source, &overrides)?;
    let canonical = |mask: usize| {
        let mut m = mask;
        for (i, r) in requires.iter().enumerate() {
            if let Some(r) = r {
                let off = (mask >> r) & 1 == 0 || excludes[i].iter().any(|x| (mask >> x) & 1 == 1);
                if off {
                    m &= !(1 << i);
                }
            }
        }
        m
    };
    let variants = 1usize << overrides.len();
    let masks: Vec<usize> = (0..variants).filter(|&m| canonical(m) == m).collect();
    let spirv = spirv_variants(path, (&module, &info), &overrides, &masks)?;
    let packed = pack(out_dir, &stem, &spirv)?;

    let shader = Shader {
        file: &file,
        stem: &stem,
        module: &module,
        info: &info,
        overrides: &overrides,
        requires: &requires,
        canonical: (0..variants).map(canonical).collect(),
        packed: &packed,
    };
    reflect(&shader)
}

/// For each override, the one it requires and those it excludes.
type OverrideRules = (Vec<Option<usize>>, Vec<Vec<usize>>);

/// The `// requires OTHER; excludes A B` clauses of `source`'s override declarations: for each
/// override, the one it requires and those it excludes (indices into `overrides`).
fn override_rules(
    path: &Path,
    source: &str,
    overrides: &[String],
) -> Result<OverrideRules, String> {
    // An override declared with a trailing `// requires OTHER` means nothing while OTHER is off,
    // and with `// requires OTHER; excludes A B` nothing while A or B is on either: such
    // combinations share the SPIR-V of the one with the override off.
    let mut requires: Vec<Option<usize>> = vec![None; overrides.len()];
    let mut excludes: Vec<Vec<usize>> = vec![Vec::new(); overrides.len()];
    for line in source.lines() {
        let l = line.trim_start();
        let (Some(rest), Some((_, clause))) =
            (l.strip_prefix("override "), l.split_once("// requires "))
        else {
            continue;
        };
        let name = rest.split(':').next().unwrap_or("").trim();
        let (req, excluded) = clause.split_once("; excludes ").unwrap_or((clause, ""));
        let req = req.split_whitespace().next().unwrap_or("");
        let position = |n: &str| overrides.iter().position(|o| o == n);
        let excluded: Option<Vec<usize>> = excluded.split_whitespace().map(position).collect();
        let (Some(i), Some(r), Some(x)) = (position(name), position(req), excluded) else {
            return Err(format!(
                "{}:1:1: error: `{l}`: unknown override in a requires clause",
                path.display()
            ));
        };
        requires[i] = Some(r);
        excludes[i] = x;
    }
    Ok((requires, excludes))
}

/// One SPIR-V (little-endian bytes) per variant in `masks`: bit i of a mask is the value of the
/// i-th override.
fn spirv_variants(
    path: &Path,
    (module, info): (&naga::Module, &naga::valid::ModuleInfo),
    overrides: &[String],
    masks: &[usize],
) -> Result<Vec<(usize, Vec<u8>)>, String> {
    let options = naga::back::spv::Options {
        lang_version: (1, 3),
        // No DEBUG flag: it embeds the WGSL source in each of the (up to 2048) variants.
        flags: naga::back::spv::WriterFlags::ADJUST_COORDINATE_SPACE
            | naga::back::spv::WriterFlags::LABEL_VARYINGS,
        ..Default::default()
    };
    let mut spirv: Vec<(usize, Vec<u8>)> = Vec::new();
    for &mask in masks {
        let mut constants = naga::back::PipelineConstants::default();
        for (i, name) in overrides.iter().enumerate() {
            constants.insert(name.clone(), ((mask >> i) & 1) as f64);
        }
        let (m, i) =
            naga::back::pipeline_constants::process_overrides(module, info, None, &constants)
                .map_err(|e| format!("{}:1:1: error: overrides: {e}", path.display()))?;
        let words = naga::back::spv::write_vec(&m, &i, &options, None)
            .map_err(|e| format!("{}:1:1: error: SPIR-V output: {e}", path.display()))?;
        spirv.push((mask, words.iter().flat_map(|w| w.to_le_bytes()).collect()));
    }
    Ok(spirv)
}

/// What `reflect` writes Rust constants from: a validated module, its overrides and the
/// canonical variant of every override combination.
struct Shader<'a> {
    file: &'a str,
    stem: &'a str,
    module: &'a naga::Module,
    info: &'a naga::valid::ModuleInfo,
    overrides: &'a [String],
    requires: &'a [Option<usize>],
    canonical: Vec<usize>,
    packed: &'a Packed,
}

/// Variants of a shader per compressed chunk: neighbouring variants differ in a few functions,
/// so a chunk compresses ~50× (one variant alone, ~3×), and a pipeline decompresses 16 variants
/// (~1 MB, a few ms) to read one.
const VARIANTS_PER_CHUNK: usize = 16;

/// Where `pack` put a shader's variants: per chunk file its name, per canonical variant its
/// (chunk, byte offset, byte length).
struct Packed {
    chunks: Vec<String>,
    at: std::collections::HashMap<usize, (usize, usize, usize)>,
}

/// Writes `spirv` (canonical variant → SPIR-V) as zstd-compressed chunks of
/// `VARIANTS_PER_CHUNK` variants into `out_dir`. Embedded as they are, the scene shader's ~800
/// variants (~50 MB) went into every binary that links the engine, every test among them.
fn pack(out_dir: &str, stem: &str, spirv: &[(usize, Vec<u8>)]) -> Result<Packed, String> {
    let mut packed = Packed {
        chunks: Vec::new(),
        at: std::collections::HashMap::new(),
    };
    for (k, chunk) in spirv.chunks(VARIANTS_PER_CHUNK).enumerate() {
        let mut data = Vec::new();
        for (mask, bytes) in chunk {
            packed.at.insert(*mask, (k, data.len(), bytes.len()));
            data.extend_from_slice(bytes);
        }
        let compressed = zstd::bulk::compress(&data, 9).map_err(|e| e.to_string())?;
        let name = format!("{stem}_{k}.spv.zst");
        std::fs::write(Path::new(out_dir).join(&name), compressed).map_err(|e| e.to_string())?;
        packed.chunks.push(name);
    }
    Ok(packed)
}

/// The generated module of one shader: its SPIR-V variants, override bits and dependants, named
/// constants, bindings, immediate size and entry points.
fn reflect(shader: &Shader) -> Result<(String, String), String> {
    let Shader {
        file, module, info, ..
    } = *shader;
    let stem = shader.stem;
    let mut layouter = naga::proc::Layouter::default();
    layouter
        .update(module.to_ctx())
        .map_err(|e| format!("{file}:1:1: error: layout: {e}"))?;
    let mut code = String::new();
    writeln!(code, "/// Generated from `{}`.", file).unwrap();
    writeln!(code, "pub mod {stem} {{").unwrap();
    writeln!(code, "    #[allow(unused_imports)] use super::*;").unwrap();
    writeln!(
        code,
        "    /// The override bits and named constants (no Vulkan: `crate::shader_consts`).\n    #[allow(unused_imports)]\n    pub use crate::shader_consts::{stem}::*;"
    )
    .unwrap();
    writeln!(
        code,
        "    /// SPIR-V of every override combination, indexed by the bit mask of `OVERRIDES`."
    )
    .unwrap();
    variants_code(shader, &mut code);
    bindings_code(module, info, &layouter, &mut code);
    let mut consts = String::new();
    writeln!(
        consts,
        "/// The override bits and named constants of `{}`.",
        file
    )
    .unwrap();
    writeln!(consts, "pub mod {stem} {{").unwrap();
    override_bits_code(shader, &mut consts);
    constants_code(module, &mut consts);
    writeln!(consts, "}}").unwrap();
    for ep in &module.entry_points {
        writeln!(code, "    /// Entry point `{}`.", ep.name).unwrap();
        writeln!(
            code,
            "    pub const ENTRY_{}: &std::ffi::CStr = c\"{}\";",
            ep.name.to_uppercase(),
            ep.name
        )
        .unwrap();
    }
    writeln!(code, "}}").unwrap();
    Ok((code, consts))
}

/// The SPIR-V variants, packed.
fn variants_code(shader: &Shader, code: &mut String) {
    let canonical = &shader.canonical;
    let chunks: Vec<String> = shader
        .packed
        .chunks
        .iter()
        .map(|name| format!("include_bytes!(concat!(env!(\"OUT_DIR\"), \"/{name}\"))"))
        .collect();
    writeln!(
        code,
        "    /// The variants' SPIR-V, zstd-compressed, `VARIANTS_PER_CHUNK` to a chunk.\n    pub const CHUNKS: &[&[u8]] = &[{}];",
        chunks.join(", ")
    )
    .unwrap();
    let at: Vec<String> = canonical
        .iter()
        .map(|m| {
            let (k, offset, len) = shader.packed.at[m];
            format!("({k}, {offset}, {len})")
        })
        .collect();
    writeln!(
        code,
        "    /// Per override combination: (chunk, byte offset, byte length) of its SPIR-V.\n    pub const VARIANT_AT: &[(usize, usize, usize)] = &[{}];",
        at.join(", ")
    )
    .unwrap();
    writeln!(
        code,
        "    /// The SPIR-V of override combination `mask`.\n    #[allow(dead_code)]\n    pub fn variant(mask: usize) -> Result<Vec<u8>, GpuError> {{\n        super::unpack(CHUNKS, VARIANT_AT, mask)\n    }}"
    )
    .unwrap();
    writeln!(
        code,
        "    /// SPIR-V with every boolean override on.\n    pub fn spirv() -> Result<Vec<u8>, GpuError> {{\n        variant(VARIANT_AT.len() - 1)\n    }}"
    )
    .unwrap();
}

/// The boolean overrides, each one's variant bit and each one's dependants.
fn override_bits_code(shader: &Shader, code: &mut String) {
    let Shader {
        overrides,
        requires,
        ..
    } = *shader;
    writeln!(
        code,
        "    /// The boolean overrides, bit i of a variant index = `OVERRIDES[i]`.\n    #[allow(dead_code)]\n    pub const OVERRIDES: &[&str] = &[{}];",
        overrides
            .iter()
            .map(|o| format!("\"{o}\""))
            .collect::<Vec<_>>()
            .join(", ")
    )
    .unwrap();
    for (i, o) in overrides.iter().enumerate() {
        writeln!(
            code,
            "    /// Variant bit of override `{o}`.\n    #[allow(dead_code)]\n    pub const BIT_{}: usize = 1 << {i};",
            o.to_uppercase()
        )
        .unwrap();
    }
    for (r, o) in overrides.iter().enumerate() {
        let dependents: Vec<String> = (0..overrides.len())
            .filter(|&i| requires[i] == Some(r))
            .map(|i| format!("BIT_{}", overrides[i].to_uppercase()))
            .collect();
        if !dependents.is_empty() {
            writeln!(
                code,
                "    /// `{o}` and the overrides declared `// requires {o}`.\n    #[allow(dead_code)]\n    pub const WITH_{}: usize = BIT_{} | {};",
                o.to_uppercase(),
                o.to_uppercase(),
                dependents.join(" | ")
            )
            .unwrap();
        }
    }
}

/// The shader's named scalar constants as Rust constants.
fn constants_code(module: &naga::Module, code: &mut String) {
    for (_, c) in module.constants.iter() {
        let Some(name) = &c.name else { continue };
        let value = match module.global_expressions[c.init] {
            naga::Expression::Literal(naga::Literal::U32(v)) => format!("u32 = {v}"),
            naga::Expression::Literal(naga::Literal::I32(v)) => format!("i32 = {v}"),
            naga::Expression::Literal(naga::Literal::F32(v)) => format!("f32 = {v:?}"),
            _ => continue,
        };
        writeln!(
            code,
            "    /// The shader's `const {name}`.\n    #[allow(dead_code)]\n    pub const {name}: {value};"
        )
        .unwrap();
    }
}

/// Every resource binding (group, binding, kind, size, stages) and the immediate block's size.
fn bindings_code(
    module: &naga::Module,
    info: &naga::valid::ModuleInfo,
    layouter: &naga::proc::Layouter,
    code: &mut String,
) {
    let mut bindings = Vec::new();
    let mut immediate_size = 0u32;
    for (handle, var) in module.global_variables.iter() {
        let name = var.name.clone().unwrap_or_default().to_uppercase();
        let ty = &module.types[var.ty];
        let size = layouter[var.ty].size;
        if var.space == naga::AddressSpace::Immediate {
            immediate_size = size;
            continue;
        }
        let Some(b) = &var.binding else { continue };
        let kind = match (&var.space, &ty.inner) {
            (naga::AddressSpace::Uniform, _) => "BindingKind::UniformBuffer",
            (naga::AddressSpace::Storage { .. }, _) => "BindingKind::StorageBuffer",
            (_, naga::TypeInner::Sampler { comparison: true }) => "BindingKind::ComparisonSampler",
            (_, naga::TypeInner::Sampler { comparison: false }) => "BindingKind::Sampler",
            (_, naga::TypeInner::Image { class, .. }) => match class {
                naga::ImageClass::Depth { .. } => "BindingKind::DepthTexture",
                _ => "BindingKind::Texture",
            },
            _ => "BindingKind::Other",
        };
        // Which stages use it.
        let mut vertex = false;
        let mut fragment = false;
        for (i, ep) in module.entry_points.iter().enumerate() {
            let used = !info.get_entry_point(i)[handle].is_empty();
            match ep.stage {
                naga::ShaderStage::Vertex => vertex |= used,
                naga::ShaderStage::Fragment => fragment |= used,
                _ => {}
            }
        }
        writeln!(
            code,
            "    /// `{}`: group {}, binding {}.",
            name.to_lowercase(),
            b.group,
            b.binding
        )
        .unwrap();
        writeln!(code, "    pub const {name}: ReflectedBinding = ReflectedBinding {{ name: \"{}\", group: {}, binding: {}, kind: {kind}, size: {size}, vertex: {vertex}, fragment: {fragment} }};", name.to_lowercase(), b.group, b.binding).unwrap();
        bindings.push(name);
    }
    writeln!(code, "    /// Every resource binding of the module.").unwrap();
    writeln!(code, "    #[allow(dead_code)]").unwrap();
    writeln!(
        code,
        "    pub const BINDINGS: &[ReflectedBinding] = &[{}];",
        bindings.join(", ")
    )
    .unwrap();
    writeln!(
        code,
        "    /// Size in bytes of the immediate (push-constant) block, 0 if none."
    )
    .unwrap();
    writeln!(
        code,
        "    pub const IMMEDIATE_SIZE: u32 = {immediate_size};"
    )
    .unwrap();
}
