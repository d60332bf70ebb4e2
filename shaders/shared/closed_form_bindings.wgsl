// The bindings of the closed-form kernels (bind_mvc.wgsl, bind_green.wgsl), a subset
// of the layout all binding kernels share (gpu::kernels::Kernels): one thread per
// point, its row written at `points[i].w` rows into `weights`, its status beside.
// Imported after bind_params, which declares `Params`.
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> cage_positions: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> topology: array<u32>;
@group(0) @binding(4) var<storage, read> points: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> weights: array<f32>;
@group(0) @binding(7) var<storage, read_write> status: array<u32>;
