//! Weights too large for one storage binding, split by rows over several buffers.
//!
//! A device bounds every storage binding (`max_storage_buffer_binding_size`, 128 MiB
//! on lavapipe) and every buffer (`max_buffer_size`), and a million-vertex mesh in
//! a 120-vertex cage has 458 MiB of weights. So each family's matrix is cut into
//! chunks of whole rows, each within both limits, bound at consecutive bindings.
//! The vertex shader finds a vertex's chunk by dividing its index by the rows per
//! chunk; WGSL cannot index bindings at run time, so [`wgsl`] writes one binding
//! per slot and a `switch` over them. The slots form one pool: the family shown
//! takes the first chunks, the compared family (the difference view) the next, and
//! unused slots hold a placeholder. Each family may use half the pool.

use crate::coords::Weights;
use std::fmt::Write as _;

/// The first binding of the pool in the scene group; below it: the frame, the
/// rest positions, both families' column displacements (in storage and, for the
/// first [`UNIFORM_COLUMNS`], again in uniform buffers), the cage and its handles.
pub const FIRST_CHUNK_BINDING: u32 = 8;
/// Columns whose displacements the blend reads from a uniform buffer: lavapipe
/// loads from a storage buffer lane by lane, each behind a branch and a bounds
/// check, and from a uniform buffer with one gather (Ogre's idle frame went from
/// 255 ms to 156 ms). 1,024 `vec4`s are 16 KiB, the least every Vulkan device
/// binds; columns past them come from the storage buffer.
pub const UNIFORM_COLUMNS: u32 = 1024;
/// Storage buffers of the scene group besides the weights.
pub const OTHER_STORAGE_BUFFERS: u32 = 5;
/// The largest pool: eight chunks per family hold 1 GiB of weights on lavapipe,
/// 2.2 million vertices in a 120-vertex cage.
pub const MAX_CHUNK_SLOTS: u32 = 16;

/// How the weights are split on one device.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ChunkLimits {
    /// Bytes one chunk may hold: the smaller of the binding and buffer limits.
    pub max_chunk_bytes: u64,
    /// Bindings in the pool (even, at least 2).
    pub slots: u32,
}

impl ChunkLimits {
    /// The split `limits` allow. The pool leaves one storage buffer of the stage to
    /// readback's output and is never smaller than one chunk per family, which
    /// `render::check_adapter` demands.
    pub fn of(limits: &wgpu::Limits) -> Self {
        let free = limits
            .max_storage_buffers_per_shader_stage
            .saturating_sub(OTHER_STORAGE_BUFFERS + 1);
        Self {
            max_chunk_bytes: limits
                .max_storage_buffer_binding_size
                .min(limits.max_buffer_size),
            slots: (free.min(MAX_CHUNK_SLOTS) / 2 * 2).max(2),
        }
    }

    /// Chunks one family may use.
    pub fn per_family(&self) -> u32 {
        self.slots / 2
    }

    /// Whole rows of `columns` f32 that fit in one chunk (0 when not even one does).
    pub fn rows_per_chunk(&self, columns: usize) -> u64 {
        self.max_chunk_bytes / (columns.max(1) as u64 * 4)
    }

    /// How `rows` × `columns` weights split, or why they cannot be held.
    pub fn split(&self, rows: usize, columns: usize) -> Result<ChunkSplit, ChunksTooLarge> {
        let rows_per_chunk = self.rows_per_chunk(columns).min(u32::MAX as u64);
        let chunks = if rows_per_chunk == 0 {
            u64::MAX
        } else {
            (rows as u64).div_ceil(rows_per_chunk).max(1)
        };
        if chunks > self.per_family() as u64 {
            return Err(ChunksTooLarge {
                needed_mib: rows as f64 * columns as f64 * 4.0 / MIB,
                rows,
                columns,
                chunk_mib: self.max_chunk_bytes as f64 / MIB,
                chunks: self.per_family(),
            });
        }
        Ok(ChunkSplit {
            rows_per_chunk: rows_per_chunk.max(1) as u32,
            chunks: chunks as u32,
        })
    }
}

const MIB: f64 = 1048576.0;

/// A weights matrix beyond what the device can bind.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error(
    "the weights matrix ({rows} mesh vertices × {columns} columns) needs {needed_mib:.1} MiB, but this GPU binds at most {chunks} × {chunk_mib:.2} MiB of weights per family; use a smaller mesh or cage"
)]
pub struct ChunksTooLarge {
    pub needed_mib: f64,
    pub rows: usize,
    pub columns: usize,
    pub chunk_mib: f64,
    pub chunks: u32,
}

/// Rows per chunk and the number of chunks of one matrix.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ChunkSplit {
    pub rows_per_chunk: u32,
    pub chunks: u32,
}

impl ChunkSplit {
    /// The values of each chunk, in order.
    pub fn chunks_of<'a>(&self, weights: &'a Weights) -> impl Iterator<Item = &'a [f32]> {
        let per_chunk = (self.rows_per_chunk as usize * weights.cols).max(1);
        weights.values.chunks(per_chunk)
    }
}

/// The pool's bindings, `chunk_weight(chunk, index)`, and the row loops of the
/// vertex shader with the chunk chosen once per row: a `switch` inside the loop,
/// once per weight, made lavapipe's blend several times slower. Appended to the
/// mesh shader (module-scope declarations may come in any order in WGSL).
pub fn wgsl(slots: u32) -> String {
    let mut out = String::from(
        "\n// Generated by render::weight_chunks: the pool of weight chunks, one binding\n\
         // each, and switches over them (bindings cannot be indexed at run time).\n",
    );
    for slot in 0..slots {
        let binding = FIRST_CHUNK_BINDING + slot;
        let _ = writeln!(
            out,
            "@group(0) @binding({binding}) var<storage, read> weight_chunk_{slot}: array<f32>;"
        );
    }
    let switch = |out: &mut String, body: &dyn Fn(u32) -> String| {
        out.push_str("    switch chunk {\n");
        for slot in 0..slots {
            let _ = writeln!(out, "        case {slot}u: {{ {} }}", body(slot));
        }
        out.push_str("        default: {}\n    }\n");
    };
    out.push_str("\nfn chunk_weight(chunk: u32, index: u32) -> f32 {\n    var weight = 0.0;\n");
    switch(&mut out, &|slot| {
        format!("weight = weight_chunk_{slot}[index];")
    });
    out.push_str("    return weight;\n}\n");
    let _ = writeln!(out, "\nconst UNIFORM_COLUMNS: u32 = {UNIFORM_COLUMNS}u;");
    // `head` + Σ_c W[row, c] · d_c over columns `first..columns` of one row, for
    // the method shown and the compared one: the first columns' d_c from the
    // uniform copy, the rest from storage.
    for (name, displacements) in [
        ("blend_row", "displacements"),
        ("blend_other_row", "other_displacements"),
    ] {
        let _ = writeln!(
            out,
            "\nfn {name}(chunk: u32, start: u32, first: u32, columns: u32, head: vec3<f32>) -> vec3<f32> {{\n    var moved = head;\n    let in_uniform = min(columns, UNIFORM_COLUMNS);"
        );
        switch(&mut out, &|slot| {
            format!(
                "for (var c = first; c < in_uniform; c++) {{ moved += weight_chunk_{slot}[start + c] * uniform_{displacements}[c].xyz; }} \
                 for (var c = max(first, in_uniform); c < columns; c++) {{ moved += weight_chunk_{slot}[start + c] * {displacements}[c].xyz; }}"
            )
        });
        out.push_str("    return moved;\n}\n");
    }
    // Σ_c W[row, c] · M_c over a row's first `columns` columns, M_c the three
    // `vec4`s from `base + 3c` (the columns of the matrix; `base` is the
    // family's column count: the matrices follow the vectors): the normalised moves of
    // coords::ColumnMoves; `columns` is 0 for a linear family, so the loop
    // costs nothing there.
    for (name, displacements) in [
        ("blend_matrix_row", "displacements"),
        ("blend_other_matrix_row", "other_displacements"),
    ] {
        let _ = writeln!(
            out,
            "\nfn {name}(chunk: u32, start: u32, columns: u32, base: u32) -> mat3x3<f32> {{\n    var m0 = vec3<f32>(0.0);\n    var m1 = vec3<f32>(0.0);\n    var m2 = vec3<f32>(0.0);"
        );
        switch(&mut out, &|slot| {
            format!(
                "for (var c = 0u; c < columns; c++) {{ let w = weight_chunk_{slot}[start + c]; let at = base + 3u * c; \
                 m0 += w * {displacements}[at].xyz; m1 += w * {displacements}[at + 1u].xyz; m2 += w * {displacements}[at + 2u].xyz; }}"
            )
        });
        out.push_str("    return mat3x3<f32>(m0, m1, m2);\n}\n");
    }
    out.push_str(
        "\nfn lowest_in_row(chunk: u32, start: u32, columns: u32, stride: u32) -> f32 {\n    var lowest = 3.4e38;\n",
    );
    switch(&mut out, &|slot| {
        format!(
            "for (var c = 0u; c < columns; c += stride) {{ lowest = min(lowest, weight_chunk_{slot}[start + c]); }}"
        )
    });
    out.push_str("    return lowest;\n}\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits(binding: u64, buffers: u32) -> ChunkLimits {
        ChunkLimits::of(&wgpu::Limits {
            max_storage_buffer_binding_size: binding,
            max_storage_buffers_per_shader_stage: buffers,
            ..Default::default()
        })
    }

    #[test]
    fn a_million_vertices_in_a_120_vertex_cage_take_four_lavapipe_chunks() {
        let lavapipe = limits(128 << 20, 32);
        assert_eq!(lavapipe.slots, MAX_CHUNK_SLOTS);
        let split = lavapipe.split(1_000_000, 120).expect("fits");
        assert_eq!(split.rows_per_chunk, (128 << 20) / 480);
        assert_eq!(split.chunks, 4);
    }

    #[test]
    fn small_matrices_stay_in_one_chunk_and_large_ones_are_refused_with_sizes() {
        let weak = limits(1 << 20, 8);
        assert_eq!(weak.slots, 2, "one chunk per family");
        let small = weak.split(1000, 40).expect("fits");
        assert_eq!(small.chunks, 1);
        let error = weak
            .split(10_000, 40)
            .expect_err("1.5 MiB in one 1 MiB chunk");
        let message = error.to_string();
        assert!(
            message.contains("10000 mesh vertices × 40 columns")
                && message.contains("1.5 MiB")
                && message.contains("at most 1 × 1.00 MiB"),
            "{message}"
        );
    }

    #[test]
    fn chunks_cover_the_rows_in_order() {
        let weights = Weights {
            rows: 5,
            cols: 2,
            values: (0..10).map(|v| v as f32).collect(),
        };
        let split = limits(16, 32).split(5, 2).expect("fits");
        assert_eq!((split.rows_per_chunk, split.chunks), (2, 3));
        let chunks: Vec<&[f32]> = split.chunks_of(&weights).collect();
        assert_eq!(
            chunks,
            [&[0., 1., 2., 3.][..], &[4., 5., 6., 7.], &[8., 9.]]
        );
    }
}
