//! Binding indices and buffer layouts shared with the shaders (see `gpu_layout_macro.rs`).
//! GLSL sees this as `#include "gpu_layout.glsl"`.

include!("gpu_layout_macro.rs");
include!("gpu_layout_defs.rs");

#[cfg(test)]
mod tests {
    #[test]
    fn rust_structs_match_std430() {
        let errors = super::layout_errors();
        assert!(
            errors.is_empty(),
            "layout mismatches:\n{}",
            errors.join("\n")
        );
    }

    #[test]
    fn glsl_header_declares_every_struct() {
        for name in [
            "FrameUniforms",
            "GpuLight",
            "ShadowView",
            "GpuMaterial",
            "DrawPush",
        ] {
            assert!(
                super::GLSL.contains(&format!("struct {name} {{")),
                "{name} missing"
            );
        }
    }
}
