//! Compiles every WGSL shader in `../shaders` to SPIR-V with naga, validating it on the way.
//! Nothing is checked in as SPIR-V and no external shader tool is needed. Pipeline-overridable
//! constants take their defaults, and the entry points of [`VARIANTS`] are compiled again with
//! some set, for the pipelines that need (or can skip) the code they guard; every glass fragment
//! entry point also with `SUPERSAMPLED` set (and those that count the positions they shade with
//! `COUNTED` too). Code shared by several shaders lives in
//! `../shaders/shared` and is appended to each that names it in a
//! `// #include shared/<file>.wgsl` line ([`with_includes`]). Beside each entry point's SPIR-V
//! it writes the static cost of one invocation (`<name>.cost.rs`, build/shader_cost.rs), which
//! the renderer's counted work multiplies by the invocations a frame ran, and in
//! `uniform_loops.rs` every entry point's loops that end on uniform values
//! (build/uniform_loops.rs), which a renderer test holds to the known few.

use std::path::{Path, PathBuf};
use std::{env, fs};

#[path = "build/shader_cost.rs"]
mod shader_cost;
#[path = "build/uniform_loops.rs"]
mod uniform_loops;

/// `source` with the files its `// #include <path>` lines name (relative to `shader_dir`)
/// appended in order. WGSL declarations may follow their use, so the shader's own lines keep
/// their numbers in naga's messages.
fn with_includes(source: &str, shader_dir: &Path) -> String {
    let mut out = source.to_owned();
    for line in source.lines() {
        if let Some(name) = line.trim().strip_prefix("// #include ") {
            let path = shader_dir.join(name.trim());
            println!("cargo:rerun-if-changed={}", path.display());
            let text = fs::read_to_string(&path)
                .unwrap_or_else(|e| panic!("including {}: {e}", path.display()));
            out.push('\n');
            out.push_str(&text);
        }
    }
    out
}

/// `module` with every branch whose condition is a constant (a pipeline constant once set, a
/// literal) replaced by the side taken, and what only the other side used (functions, resource
/// bindings) removed: a pipeline holds no code its constants rule out, and declares no
/// descriptor that only such code reads (the glass's set 1, `COMPENSATED`), so its layout need
/// not have it. Validated again.
fn without_constant_branches(
    mut module: naga::Module,
    info: naga::valid::ModuleInfo,
) -> Result<(naga::Module, naga::valid::ModuleInfo), String> {
    let mut pruned = false;
    let (constants, globals) = (&module.constants, &module.global_expressions);
    for function in module
        .functions
        .iter_mut()
        .map(|(_, f)| f)
        .chain(module.entry_points.iter_mut().map(|e| &mut e.function))
    {
        let expressions = &function.expressions;
        let value = |h| constant_bool(constants, globals, expressions, h);
        if take_constant_sides(&mut function.body, &value) {
            pruned = true;
            // A `let` of a side taken out names an expression no statement evaluates any more:
            // its name goes with it (compaction keeps named expressions).
            let mut evaluated = std::collections::HashSet::new();
            emitted(&function.body, &mut evaluated);
            function
                .named_expressions
                .retain(|h, _| evaluated.contains(h) || expressions[*h].needs_pre_emit());
        }
    }
    if !pruned {
        return Ok((module, info));
    }
    naga::compact::compact(&mut module, naga::compact::KeepUnused::No);
    let info =
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), info_capabilities())
            .validate(&module)
            .map_err(|e| format!("after dropping constant branches: {e:?}"))?;
    Ok((module, info))
}

/// Replaces, in `block` and the blocks inside it, each `if` whose condition `value` knows by
/// the side it takes; whether any was.
fn take_constant_sides(
    block: &mut naga::Block,
    value: &dyn Fn(naga::Handle<naga::Expression>) -> Option<bool>,
) -> bool {
    let mut pruned = false;
    for statement in block.iter_mut() {
        match statement {
            naga::Statement::If {
                condition,
                accept,
                reject,
            } => match value(*condition) {
                Some(taken) => {
                    let side = std::mem::take(if taken { accept } else { reject });
                    *statement = naga::Statement::Block(side);
                    take_constant_sides_in(statement, value);
                    pruned = true;
                }
                None => {
                    pruned |= take_constant_sides(accept, value);
                    pruned |= take_constant_sides(reject, value);
                }
            },
            naga::Statement::Block(inner) => pruned |= take_constant_sides(inner, value),
            naga::Statement::Switch { cases, .. } => {
                for case in cases {
                    pruned |= take_constant_sides(&mut case.body, value);
                }
            }
            naga::Statement::Loop {
                body, continuing, ..
            } => {
                pruned |= take_constant_sides(body, value);
                pruned |= take_constant_sides(continuing, value);
            }
            _ => {}
        }
    }
    pruned
}

/// Every expression that `block` and the blocks inside it evaluate (`Emit`, a call's result).
fn emitted(
    block: &naga::Block,
    into: &mut std::collections::HashSet<naga::Handle<naga::Expression>>,
) {
    for statement in block.iter() {
        match statement {
            naga::Statement::Emit(range) => into.extend(range.clone()),
            naga::Statement::Call {
                result: Some(result),
                ..
            } => {
                into.insert(*result);
            }
            naga::Statement::Block(inner) => emitted(inner, into),
            naga::Statement::If { accept, reject, .. } => {
                emitted(accept, into);
                emitted(reject, into);
            }
            naga::Statement::Switch { cases, .. } => {
                cases.iter().for_each(|case| emitted(&case.body, into));
            }
            naga::Statement::Loop {
                body, continuing, ..
            } => {
                emitted(body, into);
                emitted(continuing, into);
            }
            _ => {}
        }
    }
}

/// [`take_constant_sides`] inside the block `statement` just became.
fn take_constant_sides_in(
    statement: &mut naga::Statement,
    value: &dyn Fn(naga::Handle<naga::Expression>) -> Option<bool>,
) {
    if let naga::Statement::Block(inner) = statement {
        take_constant_sides(inner, value);
    }
}

/// The value of a boolean expression of a function when it is a constant: a literal, a module
/// constant (a set pipeline constant becomes one), or `!` of one.
fn constant_bool(
    constants: &naga::Arena<naga::Constant>,
    globals: &naga::Arena<naga::Expression>,
    expressions: &naga::Arena<naga::Expression>,
    h: naga::Handle<naga::Expression>,
) -> Option<bool> {
    let global = |h: naga::Handle<naga::Expression>| match globals[h] {
        naga::Expression::Literal(naga::Literal::Bool(b)) => Some(b),
        _ => None,
    };
    match expressions[h] {
        naga::Expression::Literal(naga::Literal::Bool(b)) => Some(b),
        naga::Expression::Constant(c) => global(constants[c].init),
        naga::Expression::Unary {
            op: naga::UnaryOperator::LogicalNot,
            expr,
        } => constant_bool(constants, globals, expressions, expr).map(|b| !b),
        _ => None,
    }
}

/// Entry points compiled again with pipeline-overridable constants set, written as
/// `<file>.<entry>.<suffix>.spv`: file stem, entry-point name prefix, constants and their
/// values, suffix.
type Variant = (
    &'static str,
    &'static str,
    &'static [(&'static str, f64)],
    &'static str,
);
const VARIANTS: &[Variant] = &[
    (
        "glass",
        "fs_two_surface_",
        &[("ABSORBING", 1.0)],
        "absorbing",
    ),
    ("glass", "fs_two_surface_", &[("BALL", 1.0)], "ball"),
    (
        "glass",
        "fs_two_surface_",
        &[("ABSORBING", 1.0), ("BALL", 1.0)],
        "absorbing.ball",
    ),
    ("glass", "fs_two_surface_", &[("CONVEX", 1.0)], "convex"),
    ("floor_overlay", "fs_main", &[("CAUSTICS", 1.0)], "caustics"),
    ("caustics_live", "cs_trace", &[("COUNTED", 1.0)], "counted"),
    (
        "floor_overlay",
        "fs_main",
        &[("CAUSTICS", 1.0), ("FILTERED_CAUSTICS", 1.0)],
        "caustics.filtered",
    ),
    (
        "glass",
        "fs_two_surface_",
        &[("ABSORBING", 1.0), ("CONVEX", 1.0)],
        "absorbing.convex",
    ),
    // The overlay again for a display with a segmented dimmer, writing the shadow's share as
    // alpha (`SHADOW`).
    ("floor_overlay", "fs_main", &[("SHADOW", 1.0)], "shadow"),
    (
        "floor_overlay",
        "fs_main",
        &[("SHADOW", 1.0), ("CAUSTICS", 1.0)],
        "shadow.caustics",
    ),
    (
        "floor_overlay",
        "fs_main",
        &[
            ("SHADOW", 1.0),
            ("CAUSTICS", 1.0),
            ("FILTERED_CAUSTICS", 1.0),
        ],
        "shadow.caustics.filtered",
    ),
    // The background looks again where the frame proved that every refracted ray reaches
    // the photo (`COVERED`): the paper's model and two surfaces through a ball.
    (
        "glass",
        "fs_paper_background_",
        &[("COVERED", 1.0)],
        "covered",
    ),
    (
        "glass",
        "fs_two_surface_background_",
        &[("BALL", 1.0), ("COVERED", 1.0)],
        "ball.covered",
    ),
    (
        "glass",
        "fs_two_surface_background_",
        &[("ABSORBING", 1.0), ("BALL", 1.0), ("COVERED", 1.0)],
        "absorbing.ball.covered",
    ),
    // Every glass model again with the room as its target (`ROOM`).
    ("glass", "fs_paper_", &[("ROOM", 1.0)], "room"),
    ("glass", "fs_two_surface_", &[("ROOM", 1.0)], "room"),
    (
        "glass",
        "fs_two_surface_",
        &[("ABSORBING", 1.0), ("ROOM", 1.0)],
        "absorbing.room",
    ),
    (
        "glass",
        "fs_two_surface_",
        &[("BALL", 1.0), ("ROOM", 1.0)],
        "ball.room",
    ),
    (
        "glass",
        "fs_two_surface_",
        &[("ABSORBING", 1.0), ("BALL", 1.0), ("ROOM", 1.0)],
        "absorbing.ball.room",
    ),
    (
        "glass",
        "fs_two_surface_",
        &[("CONVEX", 1.0), ("ROOM", 1.0)],
        "convex.room",
    ),
    (
        "glass",
        "fs_two_surface_",
        &[("ABSORBING", 1.0), ("CONVEX", 1.0), ("ROOM", 1.0)],
        "absorbing.convex.room",
    ),
];

/// What the shaders may use beyond WGSL's core.
fn info_capabilities() -> naga::valid::Capabilities {
    // Half floats packed two to a word (pack2x16float) are core SPIR-V for Vulkan
    // (GLSL.std.450 PackHalf2x16).
    naga::valid::Capabilities::PUSH_CONSTANT
        | naga::valid::Capabilities::SHADER_FLOAT16_IN_FLOAT32
        // `@early_depth_test(force)` is SPIR-V's EarlyFragmentTests, core in Vulkan.
        | naga::valid::Capabilities::EARLY_DEPTH_TEST
}

fn main() {
    let shader_dir = PathBuf::from(env::var("CARGO_MANIFEST_DIR").unwrap()).join("../shaders");
    let out_dir = PathBuf::from(env::var("OUT_DIR").unwrap());
    println!("cargo:rerun-if-changed={}", shader_dir.display());

    let mut entries: Vec<_> = fs::read_dir(&shader_dir)
        .unwrap_or_else(|e| panic!("reading {}: {e}", shader_dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "wgsl"))
        .collect();
    entries.sort();
    // Every entry point's loops that end on uniform values (build/uniform_loops.rs), for the
    // renderer's test that holds them to the known few.
    let mut loops_on_uniforms = Vec::new();
    for path in entries {
        println!("cargo:rerun-if-changed={}", path.display());
        let source = with_includes(&fs::read_to_string(&path).unwrap(), &shader_dir);
        let name = path.file_stem().unwrap().to_str().unwrap().to_owned();
        let module = naga::front::wgsl::parse_str(&source).unwrap_or_else(|e| {
            panic!(
                "{}",
                e.emit_to_string_with_path(&source, path.to_str().unwrap())
            )
        });
        let info =
            naga::valid::Validator::new(naga::valid::ValidationFlags::all(), info_capabilities())
                .validate(&module)
                .unwrap_or_else(|e| {
                    panic!(
                        "{}",
                        e.emit_to_string_with_path(&source, path.to_str().unwrap())
                    )
                });
        let mut outputs = vec![(
            naga::back::PipelineConstants::default(),
            String::new(),
            None,
        )];
        for &(file, entry, set, suffix) in VARIANTS {
            if file == name {
                let mut constants = naga::back::PipelineConstants::default();
                for &(constant, value) in set {
                    constants.insert(constant.to_owned(), value);
                }
                outputs.push((constants, format!(".{suffix}"), Some(entry)));
            }
        }
        // Every glass entry point again over several positions per pixel (`SUPERSAMPLED`).
        if name == "glass" {
            let supersampled: Vec<_> = outputs
                .iter()
                .map(|(constants, suffix, only)| {
                    let mut constants = constants.clone();
                    constants.insert("SUPERSAMPLED".to_owned(), 1.0);
                    (
                        constants,
                        format!("{suffix}.supersampled"),
                        Some(only.unwrap_or("fs_")),
                    )
                })
                .collect();
            outputs.extend(supersampled);
            // And all of those again taking away what the eye already sees (`COMPENSATED`).
            let compensated: Vec<_> = outputs
                .iter()
                .map(|(constants, suffix, only)| {
                    let mut constants = constants.clone();
                    constants.insert("COMPENSATED".to_owned(), 1.0);
                    (
                        constants,
                        format!("{suffix}.compensated"),
                        Some(only.unwrap_or("fs_")),
                    )
                })
                .collect();
            outputs.extend(compensated);
            // The environment looks of a ball in the room over several positions, which shade
            // its light in two parts each over as many positions as it needs
            // (shared/glass_positions.wgsl), again counting the positions they shade (`COUNTED`),
            // for the frames that count their work.
            let counted: Vec<_> = outputs
                .iter()
                .filter(|(_, suffix, _)| {
                    suffix.ends_with("ball.room.supersampled")
                        || suffix.ends_with("ball.room.supersampled.compensated")
                })
                .map(|(constants, suffix, _)| {
                    let mut constants = constants.clone();
                    constants.insert("COUNTED".to_owned(), 1.0);
                    (
                        constants,
                        format!("{suffix}.counted"),
                        Some("fs_two_surface_environment_"),
                    )
                })
                .collect();
            outputs.extend(counted);
            // Every look of two surfaces through a mesh (neither a ball nor a convex gem), again
            // counting the nodes and triangles its searches visit and test (`COUNTED`).
            let mesh_counted: Vec<_> = outputs
                .iter()
                .filter(|(_, suffix, _)| {
                    let model = suffix
                        .trim_end_matches(".compensated")
                        .trim_end_matches(".supersampled");
                    ["", ".absorbing", ".room", ".absorbing.room"].contains(&model)
                })
                .map(|(constants, suffix, _)| {
                    let mut constants = constants.clone();
                    constants.insert("COUNTED".to_owned(), 1.0);
                    (
                        constants,
                        format!("{suffix}.counted"),
                        Some("fs_two_surface_"),
                    )
                })
                .collect();
            outputs.extend(mesh_counted);
        }
        for (constants, suffix, only) in outputs {
            let (module, info) =
                naga::back::pipeline_constants::process_overrides(&module, &info, None, &constants)
                    .unwrap_or_else(|e| panic!("{}{suffix}: {e}", path.display()));
            let (module, info) = without_constant_branches(module.into_owned(), info.into_owned())
                .unwrap_or_else(|e| panic!("{}{suffix}: {e}", path.display()));
            for entry in &module.entry_points {
                if only.is_some_and(|prefix| !entry.name.starts_with(prefix)) {
                    continue;
                }
                for found in uniform_loops::uniform_loops(&module, &entry.name, &entry.function) {
                    loops_on_uniforms.push((format!("{name}.{}{suffix}", entry.name), found));
                }
                let options = naga::back::spv::Options {
                    lang_version: (1, 0),
                    flags: naga::back::spv::WriterFlags::empty(),
                    ..Default::default()
                };
                let pipeline_options = naga::back::spv::PipelineOptions {
                    shader_stage: entry.stage,
                    entry_point: entry.name.clone(),
                };
                let words =
                    naga::back::spv::write_vec(&module, &info, &options, Some(&pipeline_options))
                        .unwrap_or_else(|e| panic!("{}: {}: {e}", path.display(), entry.name));
                let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
                fs::write(
                    out_dir.join(format!("{name}.{}{suffix}.spv", entry.name)),
                    bytes,
                )
                .unwrap();
                fs::write(
                    out_dir.join(format!("{name}.{}{suffix}.cost.rs", entry.name)),
                    shader_cost::entry_cost(&module, &entry.function).to_rust(),
                )
                .unwrap();
            }
        }
    }
    let table: String = loops_on_uniforms
        .iter()
        .map(|(entry, found)| format!("    ({entry:?}, {:?}),\n", found.to_string()))
        .collect();
    fs::write(out_dir.join("uniform_loops.rs"), format!("&[\n{table}]\n")).unwrap();
}
