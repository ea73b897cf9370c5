// Composite (paper §3.3): color · (1 - clamp(strength · ao, 0, 1)) + illuminated-lines specular,
// cropped from the guard-banded G-buffer into the caller's target; plus the debug views. The
// overlay entry points draw only the geometry's pixels over a host's frame, keeping its colour
// on the background, and with a depth attachment write the geometry's depth in the host's
// projection.
#import shared/fullscreen.wgsl
#import shared/nd.wgsl

// Keep in sync with `lineao::passes::composite::CompositeUniform`.
struct CompositeUniform {
    levels: Levels,
    guard: vec2<u32>,
    strength: f32,
    // 0 final, 1 AO only, 2 normals, 3 depth, 4 zoom, 5 pyramid level `debug_level`.
    debug_view: u32,
    debug_level: u32,
    // The zoom value shown as white in the zoom view.
    zoom_max: f32,
    // 0: ao_map, 1: volume_map, 2: both, brightness multiplied, 3: both, the darker.
    combine: u32,
    _pad0: u32,
    // The host projection's z and w rows (overlay with depth): depth = (x·z + y) / (z·z + w) of
    // the view-space z.
    host_depth_rows: vec4<f32>,
    // The normalized depth range, to undo nd.w.
    near: f32,
    far: f32,
    _pad1: vec2<u32>,
}

@group(0) @binding(0) var<uniform> params: CompositeUniform;
@group(0) @binding(1) var color_map: texture_2d<f32>;
@group(0) @binding(2) var specular_map: texture_2d<f32>;
@group(0) @binding(3) var ao_map: texture_2d<f32>;
@group(0) @binding(4) var zoom_map: texture_2d<f32>;
// Object-space AO (`volume_ao` pass); bound to ao_map when there is none.
@group(0) @binding(5) var volume_map: texture_2d<f32>;
@group(0) @binding(6) var nd0: texture_2d<f32>;
@group(0) @binding(7) var nd1: texture_2d<f32>;
@group(0) @binding(8) var nd2: texture_2d<f32>;
@group(0) @binding(9) var nd3: texture_2d<f32>;
@group(0) @binding(10) var nd4: texture_2d<f32>;

@vertex
fn vs_main(@builtin(vertex_index) vertex_index: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(vertex_index);
}

fn show_normal(nd: vec4<f32>) -> vec3<f32> {
    return select(nd.xyz * 0.5 + 0.5, vec3<f32>(0.0), nd_is_background(nd));
}

fn pyramid_level(k: u32, pixel: vec2<u32>) -> vec4<f32> {
    let texel = level_texel(pixel, vec2<f32>(0.0), params.levels.scale[k].xy, params.levels.size[k].xy);
    switch k {
        case 0u: { return textureLoad(nd0, texel, 0); }
        case 1u: { return textureLoad(nd1, texel, 0); }
        case 2u: { return textureLoad(nd2, texel, 0); }
        case 3u: { return textureLoad(nd3, texel, 0); }
        default: { return textureLoad(nd4, texel, 0); }
    }
}

// The shown colour of the guard-banded pixel `pixel`.
fn shade(pixel: vec2<u32>) -> vec3<f32> {
    let screen = textureLoad(ao_map, pixel, 0).r;
    let volume = textureLoad(volume_map, pixel, 0).r;
    var ao = screen;
    switch params.combine {
        case 1u: { ao = volume; }
        case 2u: { ao = 1.0 - (1.0 - screen) * (1.0 - volume); }
        case 3u: { ao = max(screen, volume); }
        default: {}
    }
    var rgb: vec3<f32>;
    switch params.debug_view {
        case 1u: { rgb = vec3<f32>(1.0 - ao); }
        case 2u: { rgb = show_normal(textureLoad(nd0, pixel, 0)); }
        case 3u: { rgb = vec3<f32>(textureLoad(nd0, pixel, 0).w); }
        case 4u: { rgb = vec3<f32>(textureLoad(zoom_map, pixel, 0).r / params.zoom_max); }
        case 5u: { rgb = show_normal(pyramid_level(params.debug_level, pixel)); }
        default: {
            let color = textureLoad(color_map, pixel, 0).rgb;
            let specular = textureLoad(specular_map, pixel, 0).r;
            rgb = color * (1.0 - clamp(params.strength * ao, 0.0, 1.0)) + vec3<f32>(specular);
        }
    }
    return rgb;
}

@fragment
fn fs_main(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    return vec4<f32>(shade(vec2<u32>(position.xy) + params.guard), 1.0);
}

// The geometry's pixel of the G-buffer under `position`; background pixels are discarded, so
// the host's colour (and depth) stay.
fn overlay_pixel(position: vec4<f32>) -> vec2<u32> {
    let pixel = vec2<u32>(position.xy) + params.guard;
    if nd_is_background(textureLoad(nd0, pixel, 0)) {
        discard;
    }
    return pixel;
}

@fragment
fn fs_overlay(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    return vec4<f32>(shade(overlay_pixel(position)), 1.0);
}

struct OverlayOut {
    @location(0) color: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

@fragment
fn fs_overlay_depth(@builtin(position) position: vec4<f32>) -> OverlayOut {
    let pixel = overlay_pixel(position);
    let z = -(params.near + textureLoad(nd0, pixel, 0).w * (params.far - params.near));
    let rows = params.host_depth_rows;
    let depth = clamp((rows.x * z + rows.y) / (rows.z * z + rows.w), 0.0, 1.0);
    return OverlayOut(vec4<f32>(shade(pixel), 1.0), depth);
}
