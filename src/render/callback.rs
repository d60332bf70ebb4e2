//! The egui paint callback: egui asks for one per view and frame, and it hands
//! the work to the [`ViewportRenderer`] kept in egui_wgpu's callback resources.

use super::viewport::{FrameParams, ViewportRenderer};
use eframe::egui_wgpu;

/// The paint callback for one frame of the viewport.
pub struct ViewportCallback {
    pub params: FrameParams,
}

impl egui_wgpu::CallbackTrait for ViewportCallback {
    fn prepare(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        _screen_descriptor: &egui_wgpu::ScreenDescriptor,
        encoder: &mut wgpu::CommandEncoder,
        resources: &mut egui_wgpu::CallbackResources,
    ) -> Vec<wgpu::CommandBuffer> {
        if let Some(renderer) = resources.get_mut::<ViewportRenderer>() {
            renderer.draw_view(device, queue, encoder, &self.params);
        }
        Vec::new()
    }

    fn paint(
        &self,
        _info: egui::PaintCallbackInfo,
        pass: &mut wgpu::RenderPass<'static>,
        resources: &egui_wgpu::CallbackResources,
    ) {
        if let Some(renderer) = resources.get::<ViewportRenderer>() {
            renderer.composite(pass, self.params.view);
        }
    }
}
