// The binding kernels' uniform; `gpu::kernels::Params` in Rust (layouts compared by
// tests/shader_layouts.rs).
struct Params {
    point_count: u32,
    triangle_count: u32,
    vertex_count: u32,
    resolution: u32,
    band_rows: u32,
    max_missed: u32,
    // Offsets into `topology`: vertex → incident corners (CSR).
    incidence_offsets: u32,
    incidence_entries: u32,
}
