// Cage overlay: wire edges and square vertex handles drawn over the mesh. Each is
// drawn twice: dimmed where the mesh hides it (depth test "greater"), bright where
// visible. Paired with src/render/cage.rs.

#import frame

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(3) var<storage, read> cage: array<vec4<f32>>;
// Per cage vertex: 0 idle, 1 selected, 2 hovered, 3 + 255·w a handle that
// follows the selection with weight w (soft selection).
@group(0) @binding(4) var<storage, read> handle_state: array<u32>;

struct CageVarying {
    @builtin(position) clip: vec4<f32>,
    @location(0) colour: vec3<f32>,
}

@vertex
fn vs_edge(@builtin(vertex_index) vertex: u32) -> CageVarying {
    var out: CageVarying;
    out.clip = frame.view_projection * vec4<f32>(cage[vertex].xyz, 1.0);
    // Pull lines slightly towards the camera so that they win against faces they lie on.
    out.clip.z -= 1e-4 * out.clip.w;
    out.colour = vec3<f32>(0.25, 0.75, 1.0);
    return out;
}

@vertex
fn vs_handle(@builtin(vertex_index) corner: u32, @builtin(instance_index) handle: u32) -> CageVarying {
    let corners = array<vec2<f32>, 6>(
        vec2(-1.0, -1.0), vec2(1.0, -1.0), vec2(1.0, 1.0),
        vec2(-1.0, -1.0), vec2(1.0, 1.0), vec2(-1.0, 1.0),
    );
    let state = handle_state[handle];
    var radius = frame.handle_radius_px;
    var colour = vec3<f32>(0.92, 0.92, 0.95);
    if state == 1u {
        colour = vec3<f32>(1.0, 0.55, 0.05);
        radius *= 1.4;
    } else if state == 2u {
        colour = vec3<f32>(0.3, 1.0, 0.9);
        radius *= 1.4;
    } else if state >= 3u {
        let follows = f32(state - 3u) / 255.0;
        colour = mix(colour, vec3<f32>(1.0, 0.55, 0.05), 0.25 + 0.75 * follows);
        radius *= 1.0 + 0.4 * follows;
    }
    var clip = frame.view_projection * vec4<f32>(cage[handle].xyz, 1.0);
    clip.z -= 2e-4 * clip.w;
    let offset = corners[corner] * radius * 2.0 / frame.viewport_size_px;
    clip = vec4<f32>(clip.xy + offset * clip.w, clip.zw);
    var out: CageVarying;
    out.clip = clip;
    out.colour = colour;
    return out;
}

@fragment
fn fs_visible(in: CageVarying) -> @location(0) vec4<f32> {
    return vec4<f32>(in.colour, 1.0);
}

@fragment
fn fs_hidden(in: CageVarying) -> @location(0) vec4<f32> {
    return vec4<f32>(in.colour, 0.35);
}
