//! Both GPU PMVC kernels against the CPU: the tile kernel (invocations own texels)
//! and the band kernel (invocations own triangles), at resolutions that do and do
//! not fill the tile kernel's 32 × 32-texel regions, on cages that stress each;
//! and which kernel a cage gets. Without an adapter each test says it was not
//! run, unless `PMVC_REQUIRE_GPU=1`, which turns a missing adapter into a failure.

use crate::gpu_support;
use glam::DVec3;
use gpu_support::*;
use pmvc::coords::{BindProgress, Method};
use pmvc::geometry::procedural::{comb_outline, extrude, points_inside, refine_outline, uv_sphere};
use pmvc::geometry::procedural_quads::twisted_box;
use pmvc::gpu::{Backend, BindConfig, BindError, Binder, PmvcKernel};
use std::sync::Arc;

#[test]
fn both_kernels_agree_with_the_cpu_at_resolutions_that_cut_regions_and_tiles() {
    let Some(context) = test_context("kernels by resolution") else {
        return;
    };
    // Teeth that hide one another: rays meet several triangles.
    let cage = comb();
    let points = points_inside(&cage, 60, 11, 1e-3);
    // 5: one partial tile row; 33 and 50: a full region and a sliver of the next,
    // tiles cut by the face's edge; 64: four whole regions per face.
    for resolution in [5, 33, 50, 64] {
        for kernel in [PmvcKernel::Tiles, PmvcKernel::Bands] {
            let name = format!("comb {kernel:?} {resolution}²");
            let redone =
                pmvc_kernel_agrees(&name, &context, &cage, points.clone(), kernel, resolution);
            assert_eq!(redone, 0, "{name}");
        }
    }
}

#[test]
fn the_tile_kernel_sets_up_a_large_cage_in_several_chunks() {
    let Some(context) = test_context("tiles on 1,600 vertices") else {
        return;
    };
    // Hundreds of triangles per cube face: many chunks of set-ups per region.
    let outline = refine_outline(&comb_outline(8, 1.0, 0.25, 4.0), 800);
    let cage = extrude(&outline, -0.5, 0.5);
    assert!(cage.vertex_count() >= 1500 && cage.vertex_count() <= 2048);
    let points = points_inside(&cage, 40, 6, 1e-3);
    let redone = pmvc_kernel_agrees(
        "tiles on 1,600 vertices",
        &context,
        &cage,
        points,
        PmvcKernel::Tiles,
        32,
    );
    assert_eq!(redone, 0);
}

#[test]
fn a_box_whose_triangles_span_several_faces_binds_alike_by_both_kernels() {
    let Some(context) = test_context("box, both kernels") else {
        return;
    };
    let cage = uv_sphere(1.0, 3, 4);
    let mut points = points_inside(&cage, 80, 3, 1e-3);
    points.push(DVec3::ZERO);
    for kernel in [PmvcKernel::Tiles, PmvcKernel::Bands] {
        let name = format!("coarse sphere {kernel:?}");
        let redone = pmvc_kernel_agrees(&name, &context, &cage, points.clone(), kernel, 32);
        assert_eq!(redone, 0, "{name}");
    }
}

#[test]
fn a_cage_beyond_the_tile_kernel_binds_by_bands_and_tiles_alone_are_refused() {
    let Some(context) = test_context("beyond the tile kernel") else {
        return;
    };
    // 2,102 vertices: more than the tile kernel's workgroup sums hold.
    let cage = uv_sphere(1.0, 43, 50);
    assert!(cage.vertex_count() > 2048);
    let points = points_inside(&cage, 6, 2, 1e-2);
    let redone = pmvc_kernel_agrees(
        "2,102 vertices",
        &context,
        &cage,
        points.clone(),
        PmvcKernel::Auto,
        8,
    );
    assert_eq!(redone, 0);
    refused(&context, &cage, points, "2102");
}

#[test]
fn patches_bind_by_bands_and_the_tile_kernel_alone_is_refused() {
    let Some(context) = test_context("patches and the tile kernel") else {
        return;
    };
    let cage = twisted_box(2.0, 0.6);
    assert!(cage.has_quads());
    let points = points_inside(&cage, 20, 4, 1e-2);
    let redone = pmvc_kernel_agrees(
        "patches, auto",
        &context,
        &cage,
        points.clone(),
        PmvcKernel::Auto,
        16,
    );
    assert_eq!(redone, 0);
    refused(&context, &cage, points, "bilinear patches");
}

/// `PmvcKernel::Tiles` on `cage` is an input error that says why.
fn refused(
    context: &Arc<pmvc::gpu::GpuContext>,
    cage: &pmvc::geometry::Cage,
    points: Vec<DVec3>,
    why: &str,
) {
    let input = input(cage, points, Method::Pmvc);
    let result = Binder::new(Backend::Gpu(Arc::clone(context)))
        .with_config(BindConfig {
            pmvc_kernel: PmvcKernel::Tiles,
            ..BindConfig::default()
        })
        .bind_blocking(&input, &BindProgress::default());
    match result {
        Err(BindError::InvalidInput(message)) => {
            assert!(
                message.contains("tile kernel") && message.contains(why),
                "{message}"
            );
        }
        other => panic!("expected a refusal, got {:?}", other.map(|o| o.stats)),
    }
}
