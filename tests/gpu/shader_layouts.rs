//! The WGSL structs that Rust also writes into buffers have the same layout on both
//! sides: naga's size and member offsets of `Frame` and `Params` against the
//! `#[repr(C)]` structs. Needs no GPU.

use pmvc::gpu::kernels::{kernel_sources, Params};
use pmvc::render::FrameUniform;
use std::mem::{offset_of, size_of};

/// (size, [(member, offset)]) of struct `name` in `source`.
fn wgsl_layout(source: &str, name: &str) -> (u32, Vec<(String, u32)>) {
    let module = naga::front::wgsl::parse_str(source).expect("shader parses");
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).expect("layouts compute");
    let (handle, ty) = module
        .types
        .iter()
        .find(|(_, ty)| ty.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("struct {name} in the shader"));
    let naga::TypeInner::Struct { members, span } = &ty.inner else {
        panic!("{name} is a struct");
    };
    assert_eq!(layouter[handle].size, *span);
    let members = members
        .iter()
        .map(|member| (member.name.clone().unwrap_or_default(), member.offset))
        .collect();
    (*span, members)
}

macro_rules! rust_layout {
    ($type:ty, [$($field:ident),* $(,)?]) => {
        (
            size_of::<$type>() as u32,
            vec![$((stringify!($field).to_owned(), offset_of!($type, $field) as u32)),*],
        )
    };
}

#[test]
fn frame_uniform_matches_the_wgsl_frame() {
    let rust = rust_layout!(
        FrameUniform,
        [
            view_projection,
            eye,
            handle_radius_px,
            viewport_size_px,
            colour_limit,
            cage_size,
            columns,
            weights_bound,
            highlight_outside,
            vertex_count,
            colouring,
            colouring_column,
            log_scale,
            other_columns,
            rows_per_chunk,
            other_rows_per_chunk,
            other_first_chunk,
            smooth_shading,
            vertex_columns,
            probe_width,
            vertex_column_stride,
            matrix_columns,
            other_matrix_columns,
            normals_first,
        ]
    );
    for source in [
        pmvc::render::mesh::shader_source(),
        pmvc::render::cage::shader_source(),
    ] {
        assert_eq!(wgsl_layout(&source, "Frame"), rust);
    }
}

#[test]
fn kernel_params_match_the_wgsl_params() {
    let rust = rust_layout!(
        Params,
        [
            point_count,
            triangle_count,
            vertex_count,
            resolution,
            band_rows,
            max_missed,
            incidence_offsets,
            incidence_entries,
        ]
    );
    for (name, source) in kernel_sources() {
        assert_eq!(wgsl_layout(&source, "Params"), rust, "{name}");
    }
}
