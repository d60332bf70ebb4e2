// The uniform of every viewport shader, one slot per view; `render::FrameUniform`
// in Rust (layouts compared by tests/shader_layouts.rs).
struct Frame {
    view_projection: mat4x4<f32>,
    eye: vec3<f32>,
    handle_radius_px: f32,
    viewport_size_px: vec2<f32>,
    // The magnitude at which heatmap colours saturate.
    colour_limit: f32,
    // Method distances are divided by this.
    cage_size: f32,
    // Weights columns per mesh vertex (cage vertices, plus faces for some families).
    columns: u32,
    weights_bound: u32,
    highlight_outside: u32,
    vertex_count: u32,
    // One of the COLOURING_* constants.
    colouring: u32,
    // The column shown by COLOURING_COLUMN_WEIGHT.
    colouring_column: u32,
    log_scale: u32,
    // Columns of the compared method's weights (the difference view); 0 when
    // they are not bound.
    other_columns: u32,
    // Weights rows per chunk buffer of the method shown (render::weight_chunks).
    rows_per_chunk: u32,
    // The same for the compared method.
    other_rows_per_chunk: u32,
    // The pool slot of the compared method's first chunk.
    other_first_chunk: u32,
    // 1: light with the per-vertex normals (smooth shading); 0: per face.
    smooth_shading: u32,
    // The weights columns of the cage vertices; Green coordinates' triangle
    // columns follow them. The negativity view's minimum runs over these.
    vertex_columns: u32,
    // Texels per row of the image that render::drawn reads the drawn positions from.
    probe_width: u32,
    // Columns per cage vertex: the negativity view takes every such column
    // from the first (9 for 3×3 blocks: their x-from-x entries).
    vertex_column_stride: u32,
    // Columns whose matrices the shown family's blend solves with
    // (coords::ColumnMoves, normalised); 0 for a linear move.
    matrix_columns: u32,
    // The same for the compared family.
    other_matrix_columns: u32,
    // Where the shown family's vertex normals start in its displacements: after
    // its columns' vectors and the room for their matrices.
    normals_first: u32,
}

const COLOURING_SHADED: u32 = 0u;
const COLOURING_COLUMN_WEIGHT: u32 = 1u;
const COLOURING_MOST_NEGATIVE: u32 = 2u;
const COLOURING_METHOD_DISTANCE: u32 = 3u;
