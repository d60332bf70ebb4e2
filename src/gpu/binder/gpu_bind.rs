//! One bind on a GPU: device buffers, batches of rows, flagged rows redone on the
//! CPU, and typed readback.

use super::buffers::{byte_len, cpu_rows, entry, padded, scoped};
use super::topology::{topology, Topology};
use super::{BatchSize, BindConfig, BindError, BindInput, BindOutput, BindStats, GpuWeights};
use crate::coords::{cubemap::TexelTable, BindProgress, Weights};
use crate::geometry::{bounds_of, PointClass};
use crate::gpu::backend_choice::Work;
use crate::gpu::context::GpuContext;
use crate::gpu::kernels::{Kernel, Params, BAND_TEXELS, FALLBACK, WORKGROUP_SIZE};
use crate::gpu::GpuError;
use glam::DVec3;
use std::time::Instant;

/// Largest share of the device limits one batch buffer may take. PMVC keeps 6 floats
/// per cage triangle per row (8 per patch or triangle on a cage with quads), so a
/// 3,000-triangle cage fits about 3,600 rows: few enough batches that their round
/// trips stay a small part of a bind.
const MAX_BATCH_BUFFER_BYTES: u64 = 256 << 20;

/// Device buffers and state of one GPU bind.
pub(super) struct GpuBind<'a> {
    context: &'a GpuContext,
    input: &'a BindInput,
    config: BindConfig,
    kernel: Kernel,
    /// The quad pipeline: PMVC with quads as bilinear patches.
    patches: bool,
    /// PMVC by the tile kernel (else by bands).
    tiles: bool,
    centre: DVec3,
    rows: usize,
    cols: usize,
    capacity: usize,
    params: Params,
    bind_group: wgpu::BindGroup,
    params_buffer: wgpu::Buffer,
    points_buffer: wgpu::Buffer,
    weights_buffer: wgpu::Buffer,
    status_buffer: wgpu::Buffer,
    weights_readback: Option<wgpu::Buffer>,
    status_readback: wgpu::Buffer,
    resident: Option<wgpu::Buffer>,
}

impl<'a> GpuBind<'a> {
    pub(super) fn new(
        context: &'a GpuContext,
        input: &'a BindInput,
        config: BindConfig,
    ) -> Result<Self, BindError> {
        let kernels = context.kernels()?;
        if let Some(failure) = context.failure() {
            return Err(failure.into());
        }
        let rows = input.points.len();
        // The cage the family binds: quads as patches, or split (`--triangulate`).
        let cage = input.options.cage_to_bind(&input.cage);
        // A weights row: one column per cage vertex, then for Green coordinates
        // one per cage triangle.
        let cols = input.options.method.columns(&cage);
        let method = input.options.method;
        let kernel = Kernel::for_cage(method, &cage).ok_or(BindError::NoGpuKernel { method })?;
        let resolution = input.options.resolution.max(1);
        if kernel == Kernel::Pmvc && resolution > BAND_TEXELS {
            return Err(BindError::ResolutionTooHigh {
                asked: resolution,
                max: BAND_TEXELS,
            });
        }
        let limits = &context.limits;
        let limit = limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size);
        let topology = topology(&cage, kernel, resolution, rows);
        let patches = topology.corners == 4;
        let tiles = kernel == Kernel::Pmvc
            && config
                .pmvc_kernel
                .takes_tiles(&Work::of(input.options, rows, &input.cage))
                .map_err(BindError::InvalidInput)?;
        if kernel == Kernel::Pmvc && !tiles {
            context.pmvc_bands(patches)?;
        }
        // The band kernel's corner sums per primitive, for the whole sphere and
        // for the current band.
        let sums_per_row = if kernel == Kernel::Pmvc && !tiles {
            2 * topology.corners * topology.primitives()
        } else {
            0
        };
        let widest_row = (cols.max(sums_per_row).max(4) * 4) as u64;
        if widest_row > limit {
            return Err(GpuError::TooLarge {
                what: "one row of the bind",
                needed: widest_row,
                limit,
            }
            .into());
        }
        let cage_bytes = [
            ("the cage positions", byte_len::<[f32; 4]>(cols)),
            ("the cage topology", byte_len::<u32>(topology.words.len())),
        ];
        for (what, needed) in cage_bytes {
            if needed > limit {
                return Err(GpuError::TooLarge {
                    what,
                    needed,
                    limit,
                }
                .into());
            }
        }
        let max_groups = limits.max_compute_workgroups_per_dimension as usize;
        let dispatch_cap = if kernel == Kernel::Pmvc {
            max_groups
        } else {
            max_groups * WORKGROUP_SIZE as usize
        };
        let capacity = ((limit.min(MAX_BATCH_BUFFER_BYTES) / widest_row) as usize)
            .min(dispatch_cap)
            .min(rows)
            .max(1);

        let (lo, hi) = bounds_of(cage.positions());
        // Relative to the cage centre, so f32 keeps the precision of the differences.
        let centre = 0.5 * (lo + hi);
        let table = TexelTable::new(resolution);
        scoped(&context.device, || {
            let device = &context.device;
            // Not `create_buffer_init`: it panics when the device is lost.
            let storage = |label: &str, contents: &[u8]| {
                let buffer = device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size: contents.len() as u64,
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                context.queue.write_buffer(&buffer, 0, contents);
                buffer
            };
            let positions: Vec<[f32; 4]> = cage
                .positions()
                .iter()
                .map(|&p| {
                    let p = (p - centre).as_vec3();
                    [p.x, p.y, p.z, 0.0]
                })
                .collect();
            let positions = storage("cage positions", bytemuck::cast_slice(&padded(positions)));
            let Topology {
                words,
                params,
                corners,
            } = topology;
            let topology = storage("cage topology", bytemuck::cast_slice(&padded(words)));
            let texels: Vec<f32> = if kernel == Kernel::Pmvc {
                table
                    .solid_angle_over_length
                    .iter()
                    .map(|&v| v as f32)
                    .collect()
            } else {
                Vec::new()
            };
            let texels = storage("texel table", bytemuck::cast_slice(&padded(texels)));
            let buffer = |label: &str, size: u64, usage: wgpu::BufferUsages| {
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size,
                    usage,
                    mapped_at_creation: false,
                })
            };
            use wgpu::BufferUsages as U;
            let params_buffer = buffer(
                "bind params",
                std::mem::size_of::<Params>() as u64,
                U::UNIFORM | U::COPY_DST,
            );
            let points_buffer = buffer(
                "bind points",
                byte_len::<[f32; 4]>(capacity),
                U::STORAGE | U::COPY_DST,
            );
            let sums = buffer(
                "triangle sums",
                byte_len::<f32>(capacity * sums_per_row),
                U::STORAGE,
            );
            let weights_bytes = byte_len::<f32>(capacity * cols);
            let weights_buffer = buffer(
                "batch weights",
                weights_bytes,
                U::STORAGE | U::COPY_SRC | U::COPY_DST,
            );
            let status_bytes = byte_len::<u32>(capacity);
            let status_buffer = buffer("batch status", status_bytes, U::STORAGE | U::COPY_SRC);
            let weights_readback = config
                .cpu_weights
                .then(|| buffer("weights readback", weights_bytes, U::MAP_READ | U::COPY_DST));
            let status_readback =
                buffer("status readback", status_bytes, U::MAP_READ | U::COPY_DST);
            let resident = if config.gpu_buffer {
                let needed = byte_len::<f32>(rows * cols);
                let resident_limit = limits
                    .max_storage_buffer_binding_size
                    .min(limits.max_buffer_size);
                if needed > resident_limit {
                    return Err(GpuError::TooLarge {
                        what: "the GPU weights matrix",
                        needed,
                        limit: resident_limit,
                    });
                }
                // VERTEX: the viewport reads rows as vertex attributes too.
                let usage = U::STORAGE | U::COPY_SRC | U::COPY_DST | U::VERTEX;
                Some(buffer("weights", needed, usage))
            } else {
                None
            };
            let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("pmvc bind"),
                layout: &kernels.layout,
                entries: &[
                    entry(0, &params_buffer),
                    entry(1, &positions),
                    entry(2, &topology),
                    entry(3, &texels),
                    entry(4, &points_buffer),
                    entry(5, &sums),
                    entry(6, &weights_buffer),
                    entry(7, &status_buffer),
                ],
            });
            Ok(Self {
                context,
                input,
                config,
                kernel,
                patches: corners == 4,
                tiles,
                centre,
                rows,
                cols,
                capacity,
                params,
                bind_group,
                params_buffer,
                points_buffer,
                weights_buffer,
                status_buffer,
                weights_readback,
                status_readback,
                resident,
            })
        })
        .map_err(BindError::from)
    }

    pub(super) fn run(self, progress: &BindProgress) -> Result<BindOutput, BindError> {
        let mut weights = self
            .config
            .cpu_weights
            .then(|| Weights::zeros(self.rows, self.cols));
        let mut stats = BindStats {
            // Which PMVC kernel computed the rows goes with them (W.json's
            // "device"): the two differ where a ray grazes an edge.
            device: match (self.kernel, self.tiles) {
                (Kernel::Pmvc, true) => format!("{}, PMVC tile kernel", self.context.describe()),
                (Kernel::Pmvc, false) => format!("{}, PMVC band kernel", self.context.describe()),
                _ => self.context.describe(),
            },
            ..BindStats::default()
        };
        let mut batch_rows = match self.config.batch {
            BatchSize::Fixed(rows) => rows,
            // A first guess that keeps the first batch short even for large cages:
            // a row costs about one triangle loop (MVC) or a few hundred per
            // triangle (PMVC: bounds walks over the cube map).
            BatchSize::Adaptive { .. } => {
                let triangles = self.input.cage.triangle_count().max(1);
                match self.kernel {
                    Kernel::Pmvc => 2048 / triangles,
                    Kernel::Mvc | Kernel::Green => 65536 / triangles,
                }
            }
        }
        .clamp(1, self.capacity);
        let mut start = 0;
        while start < self.rows {
            if progress.is_cancelled() {
                return Err(BindError::Cancelled);
            }
            let end = (start + batch_rows).min(self.rows);
            let clock = Instant::now();
            self.batch(start..end, weights.as_mut(), &mut stats)?;
            stats.batches += 1;
            progress.advance(end - start);
            if let BatchSize::Adaptive { target } = self.config.batch {
                let elapsed = clock.elapsed().as_secs_f64().max(1e-4);
                // Up to 8× larger: the first batches are short by design, and on a
                // fast GPU their time is mostly latency, so doubling took a dozen
                // batches to reach a useful size. Never beyond the target's rows.
                let scale = (target.as_secs_f64() / elapsed).clamp(0.5, 8.0);
                batch_rows = ((batch_rows as f64 * scale) as usize).clamp(1, self.capacity);
            }
            start = end;
        }
        if progress.is_cancelled() {
            return Err(BindError::Cancelled);
        }
        if self.resident.is_some() {
            // Flush the CPU rows written into the resident matrix.
            scoped(&self.context.device, || {
                self.context.queue.submit([]);
                self.wait()
            })?;
        }
        Ok(BindOutput {
            weights,
            gpu_weights: self.resident.map(|buffer| GpuWeights {
                buffer,
                rows: self.rows,
                cols: self.cols,
            }),
            stats,
        })
    }

    fn wait(&self) -> Result<(), GpuError> {
        self.context
            .device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| GpuError::Internal(e.to_string()))?;
        match self.context.failure() {
            Some(failure) => Err(failure),
            None => Ok(()),
        }
    }

    /// Bind rows `range`: CPU rows first, then one dispatch for the inside rows.
    fn batch(
        &self,
        range: std::ops::Range<usize>,
        mut weights: Option<&mut Weights>,
        stats: &mut BindStats,
    ) -> Result<(), GpuError> {
        let input = self.input;
        let cols = self.cols;
        let row_bytes = (cols * 4) as u64;
        let (inside, cpu): (Vec<usize>, Vec<usize>) = range
            .clone()
            .partition(|&row| matches!(input.classes[row], PointClass::Inside));
        let cpu_values = cpu_rows(input, &cpu);
        stats.cpu_rows += cpu.len();
        stats.gpu_rows += inside.len();
        if let Some(weights) = weights.as_deref_mut() {
            for (k, &row) in cpu.iter().enumerate() {
                weights.values[row * cols..(row + 1) * cols]
                    .copy_from_slice(&cpu_values[k * cols..(k + 1) * cols]);
            }
        }
        if inside.is_empty() && self.resident.is_none() {
            return Ok(());
        }
        let queue = &self.context.queue;
        let mut waited = std::time::Duration::ZERO;
        let flagged = scoped(&self.context.device, || {
            if self.resident.is_some() {
                // The batch block is copied whole into the resident matrix.
                for (k, &row) in cpu.iter().enumerate() {
                    queue.write_buffer(
                        &self.weights_buffer,
                        (row - range.start) as u64 * row_bytes,
                        bytemuck::cast_slice(&cpu_values[k * cols..(k + 1) * cols]),
                    );
                }
            }
            let mut encoder =
                self.context
                    .device
                    .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                        label: Some("pmvc batch"),
                    });
            let status_bytes = (inside.len() * 4) as u64;
            let block_bytes = range.len() as u64 * row_bytes;
            if !inside.is_empty() {
                let points: Vec<[f32; 4]> = inside
                    .iter()
                    .map(|&row| {
                        let p = (input.points[row] - self.centre).as_vec3();
                        [p.x, p.y, p.z, (row - range.start) as f32]
                    })
                    .collect();
                queue.write_buffer(&self.points_buffer, 0, bytemuck::cast_slice(&points));
                let params = Params {
                    point_count: inside.len() as u32,
                    ..self.params
                };
                queue.write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&params));
                let kernels = self.context.kernels()?;
                {
                    let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                        label: Some("pmvc bind"),
                        timestamp_writes: None,
                    });
                    pass.set_bind_group(0, &self.bind_group, &[]);
                    let groups = match self.kernel {
                        Kernel::Pmvc => {
                            pass.set_pipeline(if self.tiles {
                                &kernels.pmvc_tiles
                            } else {
                                self.context.pmvc_bands(self.patches)?
                            });
                            inside.len() as u32
                        }
                        Kernel::Mvc => {
                            pass.set_pipeline(&kernels.mvc);
                            (inside.len() as u32).div_ceil(WORKGROUP_SIZE)
                        }
                        Kernel::Green => {
                            pass.set_pipeline(&kernels.green);
                            (inside.len() as u32).div_ceil(WORKGROUP_SIZE)
                        }
                    };
                    pass.dispatch_workgroups(groups, 1, 1);
                }
                encoder.copy_buffer_to_buffer(
                    &self.status_buffer,
                    0,
                    &self.status_readback,
                    0,
                    status_bytes,
                );
                if let Some(readback) = &self.weights_readback {
                    encoder.copy_buffer_to_buffer(
                        &self.weights_buffer,
                        0,
                        readback,
                        0,
                        block_bytes,
                    );
                }
            }
            if let Some(resident) = &self.resident {
                if block_bytes > 0 {
                    encoder.copy_buffer_to_buffer(
                        &self.weights_buffer,
                        0,
                        resident,
                        range.start as u64 * row_bytes,
                        block_bytes,
                    );
                }
            }
            let submitted = Instant::now();
            queue.submit([encoder.finish()]);
            if inside.is_empty() {
                return self.wait().map(|()| Vec::new());
            }
            let status: Vec<u32> = read_back(self, &self.status_readback, status_bytes)?;
            waited = submitted.elapsed();
            if let (Some(readback), Some(weights)) =
                (&self.weights_readback, weights.as_deref_mut())
            {
                // Straight from the mapped buffer into the rows: a large cage's
                // matrix is hundreds of MiB, and a second copy cost more than the kernel.
                with_mapped(self, readback, block_bytes, |block: &[f32]| {
                    for &row in &inside {
                        let local = row - range.start;
                        weights.values[row * cols..(row + 1) * cols]
                            .copy_from_slice(&block[local * cols..(local + 1) * cols]);
                    }
                })?;
            }
            Ok(inside
                .iter()
                .zip(&status)
                .filter(|(_, &status)| status & FALLBACK != 0)
                .map(|(&row, _)| row)
                .collect::<Vec<usize>>())
        })?;
        stats.gpu_wait += waited;

        if !flagged.is_empty() {
            let values = cpu_rows(input, &flagged);
            stats.cpu_rows += flagged.len();
            stats.gpu_rows -= flagged.len();
            for (k, &row) in flagged.iter().enumerate() {
                let value = &values[k * cols..(k + 1) * cols];
                if let Some(weights) = weights.as_deref_mut() {
                    weights.values[row * cols..(row + 1) * cols].copy_from_slice(value);
                }
                if let Some(resident) = &self.resident {
                    queue.write_buffer(
                        resident,
                        row as u64 * row_bytes,
                        bytemuck::cast_slice(value),
                    );
                }
            }
        }
        Ok(())
    }
}

/// Map `buffer`, wait for the device, and copy out its first `bytes` as `T`s.
fn read_back<T: bytemuck::Pod>(
    bind: &GpuBind<'_>,
    buffer: &wgpu::Buffer,
    bytes: u64,
) -> Result<Vec<T>, GpuError> {
    with_mapped(bind, buffer, bytes, |values: &[T]| values.to_vec())
}

/// Map `buffer`, wait for the device, and hand its first `bytes` to `read` as `T`s.
fn with_mapped<T: bytemuck::Pod, R>(
    bind: &GpuBind<'_>,
    buffer: &wgpu::Buffer,
    bytes: u64,
    read: impl FnOnce(&[T]) -> R,
) -> Result<R, GpuError> {
    let (sender, receiver) = std::sync::mpsc::channel();
    buffer.map_async(wgpu::MapMode::Read, 0..bytes, move |result| {
        let _ = sender.send(result);
    });
    bind.wait()?;
    match receiver.recv() {
        Ok(Ok(())) => {}
        Ok(Err(error)) => return Err(GpuError::Readback(error.to_string())),
        Err(_) => return Err(GpuError::Readback("the map callback never ran".into())),
    }
    let result = {
        let view = buffer
            .get_mapped_range(0..bytes)
            .map_err(|e| GpuError::Readback(e.to_string()))?;
        // Mapped ranges are aligned for any `T` a kernel writes; copy if one is not.
        match bytemuck::try_cast_slice::<u8, T>(&view) {
            Ok(values) => read(values),
            Err(_) => read(&bytemuck::pod_collect_to_vec::<u8, T>(&view)),
        }
    };
    buffer.unmap();
    Ok(result)
}
