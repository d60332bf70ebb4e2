//! What the viewport's shaders computed, read back (tests and checks): in scene
//! coordinates, as the GPU holds them ([`ViewportRenderer::scene_origin`]).

use super::{
    DrawnPositions, FrameParams, Readback, RenderError, Shading, ViewportRenderer, WeightSlot,
    READBACK_SLOT,
};
use crate::coords::Method;
use crate::render::scene_gpu::{ReadBack, FRAME_SLOT_BYTES};
use glam::{Mat4, Vec3};

impl ViewportRenderer {
    /// The deformed mesh positions (in scene coordinates, [`Self::scene_origin`]),
    /// colouring values and colours exactly as the shaders compute them for `shading`.
    pub fn read_back(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        shading: &Shading,
    ) -> Result<ReadBack, RenderError> {
        let (bind_group, offset) = self.readback_bind_group(device, queue, shading)?;
        let slots = self.chunk_limits.slots;
        let readback =
            (self.readback).get_or_insert_with(|| Readback::new(device, &self.scene_layout, slots));
        let scene = self.scene.as_ref().ok_or(RenderError::NoScene)?;
        readback
            .run(device, queue, scene, &bind_group, offset)
            .map_err(|_| RenderError::ReadBack)
    }

    /// `method`'s deformed mesh positions as the vertex shader draws them, in
    /// scene coordinates: read as vertex attributes where the viewport reads
    /// them so ([`Self::attribute_columns`]).
    pub fn read_back_drawn(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        method: Method,
    ) -> Result<Vec<Vec3>, RenderError> {
        let shading = Shading {
            method,
            ..Default::default()
        };
        let (bind_group, offset) = self.readback_bind_group(device, queue, &shading)?;
        let scene = self.scene.as_ref().ok_or(RenderError::NoScene)?;
        let weights = scene
            .slots
            .get(&method)
            .and_then(WeightSlot::attribute_weights);
        let slots = self.chunk_limits.slots;
        let drawn = (self.drawn)
            .get_or_insert_with(|| DrawnPositions::new(device, &self.scene_layout, slots));
        drawn
            .run(device, queue, scene, &bind_group, offset, weights)
            .map_err(|_| RenderError::ReadBack)
    }

    /// The weights columns `method`'s rows are drawn with from vertex attributes
    /// (the rest from storage); `None` when they are all read from storage.
    pub fn attribute_columns(&self, method: Method) -> Option<u32> {
        let slot = self.scene.as_ref()?.slots.get(&method)?;
        Some(slot.attributes?.attribute_columns())
    }

    /// The readback slot of the frame uniform set for `shading`, and the scene's
    /// bind group with its offset.
    fn readback_bind_group(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        shading: &Shading,
    ) -> Result<(wgpu::BindGroup, u32), RenderError> {
        let params = FrameParams {
            view: READBACK_SLOT,
            shading: *shading,
            view_projection: Mat4::IDENTITY,
            eye: Vec3::ZERO,
            size_px: [1, 1],
            handle_radius_px: 0.0,
            highlight_outside: false,
            show_cage: false,
            wireframe: false,
            smooth_shading: false,
        };
        let uniform = self.frame_uniform(&params);
        self.write_frame_slot(queue, READBACK_SLOT, &uniform);
        let scene = self.scene.as_mut().ok_or(RenderError::NoScene)?;
        let bind_group = scene.bind_group(
            device,
            &self.scene_layout,
            &self.frame,
            shading.method,
            shading.against,
        );
        let offset = (READBACK_SLOT as u64 * FRAME_SLOT_BYTES) as u32;
        Ok((bind_group.clone(), offset))
    }

    /// `method`'s smooth-shading normals as last computed (for tests).
    pub fn read_back_normals(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        method: Method,
    ) -> Option<Result<Vec<Vec3>, wgpu::BufferAsyncError>> {
        crate::render::normals::read_back(device, queue, self.scene.as_ref()?, method)
    }
}
