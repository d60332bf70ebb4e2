// The bindings both PMVC kernels read (bind_pmvc.wgsl, bind_pmvc_tiles.wgsl), of
// the layout all binding kernels share (gpu::kernels::Kernels); the band kernel
// adds its corner sums at binding 5. Imported after bind_params (`Params`).
@group(0) @binding(0) var<uniform> params: Params;
// Cage vertices relative to the cage centre, xyz.
@group(0) @binding(1) var<storage, read> cage_positions: array<vec4<f32>>;
// CORNERS corners per primitive (NO_CORNER fills a triangle's fourth among
// patches), then incidence offsets (vertex_count + 1), then incident corners as
// t * CORNERS + corner.
@group(0) @binding(2) var<storage, read> topology: array<u32>;
// Ω/|d| per texel of one face (row-major, j is the row).
@group(0) @binding(3) var<storage, read> texels: array<f32>;
// xyz relative to the cage centre; w = output row within the batch.
@group(0) @binding(4) var<storage, read> points: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> weights: array<f32>;
// Per point: 0, or FALLBACK when the CPU must redo the row (too many rays
// escaped, or no positive total).
@group(0) @binding(7) var<storage, read_write> status: array<u32>;

var<workgroup> partial_totals: array<f32, WORKGROUP_SIZE>;
var<workgroup> summed_totals: f32;

// The sum of every invocation's `mine`, in invocation order, the same value in
// all. Called in uniform control flow. One invocation adds them up: when each
// did, every invocation's loop read all 64 from workgroup memory, which cost
// lavapipe more than the second barrier does.
fn workgroup_sum(lane: u32, mine: f32) -> f32 {
    partial_totals[lane] = mine;
    workgroupBarrier();
    if lane == 0u {
        var sum = 0.0;
        for (var k = 0u; k < WORKGROUP_SIZE; k++) {
            sum += partial_totals[k];
        }
        summed_totals = sum;
    }
    return workgroupUniformLoad(&summed_totals);
}

// Divide the point's row (at `out_base` in `weights`) by its total, or leave it
// to the CPU when `redo` is set or the total is not positive.
fn finish_row(point: u32, lane: u32, out_base: u32, row_total: f32, redo: bool) {
    if redo || !(row_total > 0.0) {
        if lane == 0u {
            status[point] = FALLBACK;
        }
        return;
    }
    if lane == 0u {
        status[point] = 0u;
    }
    let inverse_total = 1.0 / row_total;
    for (var v = lane; v < params.vertex_count; v += WORKGROUP_SIZE) {
        weights[out_base + v] *= inverse_total;
    }
}
