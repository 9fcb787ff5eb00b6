//! Compiles every shader under `glsl/` to SPIR-V and embeds it in the binary; a shader
//! with `// variant: MACRO` lines is compiled once more per line with MACRO defined.
//!
//! Shaders `#include` headers relative to themselves or to `glsl/`, plus the generated
//! `gpu_layout.glsl` (from `src/gpu_layout_defs.rs`, the one definition of bindings and
//! struct layouts). A GLSL error fails the build with `file:line: message`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

#[allow(dead_code)]
mod gpu_layout {
    include!("src/gpu_layout_macro.rs");
    include!("src/gpu_layout_defs.rs");
}

const STAGES: [(&str, shaderc::ShaderKind); 4] = [
    ("vert", shaderc::ShaderKind::Vertex),
    ("geom", shaderc::ShaderKind::Geometry),
    ("frag", shaderc::ShaderKind::Fragment),
    ("comp", shaderc::ShaderKind::Compute),
];

fn shader_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("reading {}: {e}", dir.display()))
        .map(|e| e.expect("directory entry").path())
        .collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            shader_files(&path, out);
        } else if STAGES
            .iter()
            .any(|(ext, _)| path.extension().is_some_and(|e| e == *ext))
        {
            out.push(path);
        }
    }
}

/// `glsl/passes/lighting/lighting.comp` becomes `PASSES_LIGHTING_LIGHTING_COMP`.
fn const_name(relative: &Path) -> String {
    relative
        .to_string_lossy()
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_uppercase()
            } else {
                '_'
            }
        })
        .collect()
}

/// Vulkan 1.3 / SPIR-V 1.5, optimized, with debug info; `#include` resolves
/// `gpu_layout.glsl` to `layout_header`, other names beside the includer or under `glsl_dir`.
fn compile_options<'a>(glsl_dir: &Path, layout_header: &str) -> shaderc::CompileOptions<'a> {
    let mut options = shaderc::CompileOptions::new().unwrap();
    options.set_target_env(
        shaderc::TargetEnv::Vulkan,
        shaderc::EnvVersion::Vulkan1_3 as u32,
    );
    // SPIR-V 1.6 turns `discard` into demote-to-helper, an optional feature.
    options.set_target_spirv(shaderc::SpirvVersion::V1_5);
    options.set_optimization_level(shaderc::OptimizationLevel::Performance);
    options.set_generate_debug_info();
    let glsl_dir = glsl_dir.to_path_buf();
    let layout_header = layout_header.to_string();
    options.set_include_callback(move |name, _kind, includer, _depth| {
        if name == "gpu_layout.glsl" {
            return Ok(shaderc::ResolvedInclude {
                resolved_name: "gpu_layout.glsl".into(),
                content: layout_header.clone(),
            });
        }
        let beside = Path::new(includer).parent().map(|p| p.join(name));
        let candidates = beside.into_iter().chain([glsl_dir.join(name)]);
        for candidate in candidates {
            if let Ok(content) = std::fs::read_to_string(&candidate) {
                return Ok(shaderc::ResolvedInclude {
                    resolved_name: candidate.to_string_lossy().into_owned(),
                    content,
                });
            }
        }
        Err(format!(
            "cannot find include \"{name}\" (looked beside {includer} and in glsl/)"
        ))
    });
    options
}

/// The shared scenes and references the tests read: `$VOXCONE_SHARED`, else `shared/`
/// beside the repository. Where found, the tests see `cfg(voxcone_shared)` and its path in
/// `VOXCONE_SHARED_DIR`; where not, those tests are `#[ignore]`d, so the summary counts
/// them as skipped rather than passed. Cargo cannot watch for a folder that does not exist
/// yet: after adding one, `touch build.rs` (the README says so).
fn find_shared(root: &Path) {
    println!("cargo::rustc-check-cfg=cfg(voxcone_shared)");
    println!("cargo:rerun-if-env-changed=VOXCONE_SHARED");
    let found = std::env::var_os("VOXCONE_SHARED")
        .map(PathBuf::from)
        .into_iter()
        .chain([root.join("../shared")])
        .find(|d| d.join("scenes").is_dir() && d.join("reference").is_dir());
    if let Some(dir) = found {
        let dir = dir.canonicalize().unwrap_or(dir);
        println!("cargo:rustc-cfg=voxcone_shared");
        println!("cargo:rustc-env=VOXCONE_SHARED_DIR={}", dir.display());
        // Its removal reruns this script (a watched path that vanished is stale).
        println!("cargo:rerun-if-changed={}", dir.join("reference").display());
    }
}

fn main() {
    let root = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap());
    let glsl_dir = root.join("glsl");
    let out_dir = PathBuf::from(std::env::var("OUT_DIR").unwrap());
    println!("cargo:rerun-if-changed=glsl");
    println!("cargo:rerun-if-changed=src/gpu_layout_macro.rs");
    println!("cargo:rerun-if-changed=src/gpu_layout_defs.rs");
    find_shared(&root);

    let layout_header = gpu_layout::GLSL.to_string();
    std::fs::write(out_dir.join("gpu_layout.glsl"), &layout_header).unwrap();

    let compiler = shaderc::Compiler::new().expect("shaderc compiler");
    let mut files = Vec::new();
    shader_files(&glsl_dir, &mut files);

    let mut module =
        String::from("// Generated by build.rs: SPIR-V of every shader under glsl/.\n");
    let mut failures = Vec::new();
    for path in &files {
        let relative = path.strip_prefix(&glsl_dir).unwrap();
        let kind = STAGES
            .iter()
            .find(|(ext, _)| path.extension().is_some_and(|e| e == *ext))
            .unwrap()
            .1;
        let source = std::fs::read_to_string(path).unwrap();
        // `// variant: MACRO...` lines ask for one more compile with those macros defined,
        // named with a `_MACRO...` suffix (the octree's variants of the dense GI passes).
        let variants = std::iter::once(None).chain(
            source
                .lines()
                .filter_map(|l| l.trim().strip_prefix("// variant:"))
                .map(|m| Some(m.split_whitespace().collect::<Vec<_>>())),
        );
        for variant in variants {
            let name = match &variant {
                Some(macros) => format!("{}_{}", const_name(relative), macros.join("_")),
                None => const_name(relative),
            };
            let mut options = compile_options(&glsl_dir, &layout_header);
            for m in variant.iter().flatten() {
                options.add_macro_definition(m, None);
            }
            let display = path.to_string_lossy().into_owned();
            match compiler.compile_into_spirv(&source, kind, &display, "main", Some(&options)) {
                Ok(artifact) => {
                    if artifact.get_num_warnings() > 0 {
                        for line in artifact.get_warning_messages().lines() {
                            println!("cargo:warning={line}");
                        }
                    }
                    let spv = out_dir.join(format!("{name}.spv"));
                    std::fs::write(&spv, artifact.as_binary_u8()).unwrap();
                    let with = variant
                        .map(|macros| format!(" with {}", macros.join(" and ")))
                        .unwrap_or_default();
                    writeln!(
                        module,
                        "/// SPIR-V of `glsl/{}`{with}.\npub const {name}: &[u8] = include_bytes!({:?});",
                        relative.display(),
                        spv
                    )
                    .unwrap();
                }
                Err(e) => failures.push(e.to_string()),
            }
        }
    }
    if !failures.is_empty() {
        for failure in &failures {
            eprintln!("{failure}");
        }
        eprintln!("{} shader(s) failed to compile", failures.len());
        std::process::exit(1);
    }
    std::fs::write(out_dir.join("shaders.rs"), module).unwrap();
}
