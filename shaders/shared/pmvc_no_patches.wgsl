// bind_pmvc.wgsl's patch functions for a cage of triangles (CORNERS = 3), in
// place of shared/pmvc_patches.wgsl: no primitive is a patch, and the kernel
// compiles without the patch code it would never run.

struct PatchSetup {
    face: FaceSetup,
}

fn is_patch(t: u32) -> bool {
    return false;
}

fn patch_setup(t: u32, x: vec3<f32>, axes: mat3x3<f32>) -> PatchSetup {
    var setup: PatchSetup;
    return setup;
}

fn raster_patch(setup: PatchSetup, i: u32, j: u32, band_start: u32) {}

fn claim_patch(setup: PatchSetup, t: u32, i: u32, j: u32, band_start: u32) -> vec4<f32> {
    return vec4<f32>(0.0);
}

fn claimed_patch_sums(setup: PatchSetup, t: u32, band_start: u32, band_end: u32) -> vec4<f32> {
    return vec4<f32>(0.0);
}
