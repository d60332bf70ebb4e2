//! Keyboard focus. A bare X server (no window manager: CI, containers, some
//! kiosks) gives a new window no keyboard focus, and clicking does not give it
//! either, so the shortcuts (M, F, X/Y/Z) would do nothing. egui's request goes
//! through the window manager; without one, the window asks the X server itself.

/// Frames at the start during which the window keeps asking until it has focus
/// (the first ones come before the window is mapped, when X refuses).
const STARTUP_FRAMES: u32 = 30;

/// Frames drawn, up to a limit, for asking for keyboard focus at start.
#[derive(Default)]
pub struct KeyboardFocus {
    frames: u32,
}

impl KeyboardFocus {
    /// Ask for keyboard focus at start, and on any press while the window lacks it.
    pub fn ask(&mut self, ctx: &egui::Context, frame: &eframe::Frame) {
        let (focused, pressed) = ctx.input(|i| (i.viewport().focused, i.pointer.any_pressed()));
        let starting = self.frames < STARTUP_FRAMES;
        self.frames = self.frames.saturating_add(1);
        let wanted = (starting && focused != Some(true)) || (pressed && focused == Some(false));
        if !wanted {
            return;
        }
        if self.frames == 1 || pressed {
            ctx.send_viewport_cmd(egui::ViewportCommand::Focus);
        }
        focus_without_window_manager(frame);
    }
}

/// Give the window the X server's input focus directly. Does nothing on other
/// platforms, or when it fails (not yet mapped, not X11).
#[cfg(target_os = "linux")]
fn focus_without_window_manager(frame: &eframe::Frame) {
    use raw_window_handle::{HasWindowHandle, RawWindowHandle};
    use x11rb::connection::Connection;
    use x11rb::protocol::xproto::{ConnectionExt, InputFocus};
    let Ok(handle) = frame.window_handle() else {
        return;
    };
    let window = match handle.as_raw() {
        RawWindowHandle::Xlib(xlib) => xlib.window as u32,
        RawWindowHandle::Xcb(xcb) => xcb.window.get(),
        _ => return,
    };
    let Ok((connection, _)) = x11rb::connect(None) else {
        return;
    };
    if let Ok(cookie) = connection.set_input_focus(InputFocus::PARENT, window, x11rb::CURRENT_TIME)
    {
        let _ = cookie.check();
    }
    let _ = connection.flush();
}

#[cfg(not(target_os = "linux"))]
fn focus_without_window_manager(_: &eframe::Frame) {}
