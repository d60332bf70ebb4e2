//! Small pieces of a GPU bind: CPU rows, buffer sizes and bindings, error scopes.

use super::BindInput;
use crate::coords::{self, BindProgress};
use crate::gpu::GpuError;

/// Rows the CPU computes, in f64 by the policy of [`coords::weights_at`], through
/// the same row loop as a CPU bind.
pub(super) fn cpu_rows(input: &BindInput, rows: &[usize]) -> Vec<f32> {
    let mut out = vec![0.0f32; rows.len() * input.options.columns(&input.cage)];
    // A batch's own progress: the bind advances once per batch.
    let batch_progress = BindProgress::default();
    let finished = coords::bind_rows(
        &input.points,
        &input.classes,
        &input.cage,
        input.options,
        rows,
        &mut out,
        &batch_progress,
    );
    debug_assert!(
        finished.is_ok(),
        "a batch's own progress is never cancelled"
    );
    out
}

pub(super) fn byte_len<T>(count: usize) -> u64 {
    (count * std::mem::size_of::<T>()).max(16) as u64
}

/// Pop an error scope, turning a captured error into a [`GpuError`].
fn pop_scope(scope: wgpu::ErrorScopeGuard) -> Result<(), GpuError> {
    match pollster::block_on(scope.pop()) {
        Some(error) => Err(error.into()),
        None => Ok(()),
    }
}

/// Run `body` inside out-of-memory and validation error scopes.
pub(super) fn scoped<T>(
    device: &wgpu::Device,
    body: impl FnOnce() -> Result<T, GpuError>,
) -> Result<T, GpuError> {
    let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let memory = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    let result = body();
    let memory = pop_scope(memory);
    let validation = pop_scope(validation);
    let value = result?;
    memory?;
    validation?;
    Ok(value)
}

pub(super) fn entry(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding,
        resource: buffer.as_entire_binding(),
    }
}

/// Non-empty, so that every binding has a size.
pub(super) fn padded<T: Default + Clone>(mut values: Vec<T>) -> Vec<T> {
    if values.is_empty() {
        values.push(T::default());
    }
    values
}
