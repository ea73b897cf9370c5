// The G-buffer of docs/reference.md from a host renderer's own buffers: its depth (any convention the
// inverse projection undoes: standard or reversed-Z, perspective or orthographic; MSAA samples
// resolved to the nearest), its normals if it has them (view or world space, signed or packed
// as unorm), else normals reconstructed from the depth; and its lit color. See
// `lineao::passes::nd_from_depth`.
#import shared/gbuffer.wgsl

// Keep in sync with `lineao::passes::nd_from_depth::HostUniform`.
struct HostUniform {
    inv_proj: mat4x4<f32>,
    // World to view rotation, for world-space host normals.
    view_rotation: mat4x4<f32>,
    size: vec2<f32>,
    near: f32,
    far: f32,
    f_px: f32,
    zoom_unit: f32,
    orthographic: u32,
    // The depth the host clears to: 1 (standard) or 0 (reversed-Z).
    far_depth: f32,
    _pad0: u32,
    _pad3: u32,
    _pad1: u32,
    _pad2: u32,
}

// Depth samples per pixel (`texture_depth_multisampled_2d` for more than one).
override SAMPLES: u32 = 1u;
// Host normals: 0 none (reconstructed from depth), 1 view signed, 2 view unorm (n · 0.5 + 0.5),
// 3 world signed, 4 world unorm.
override NORMALS: u32 = 0u;

@group(0) @binding(0) var<uniform> host: HostUniform;
// `lineao::passes::nd_from_depth` swaps the type for `texture_depth_multisampled_2d` under MSAA.
@group(0) @binding(1) var host_depth: texture_depth_2d;
@group(0) @binding(2) var host_normals: texture_2d<f32>;
@group(0) @binding(3) var host_color: texture_2d<f32>;
@group(0) @binding(4) var nd_out: texture_storage_2d<rgba32float, write>;
@group(0) @binding(5) var zoom_out: texture_storage_2d<r32float, write>;
@group(0) @binding(6) var color_out: texture_storage_2d<rgba16float, write>;
@group(0) @binding(7) var specular_out: texture_storage_2d<r32float, write>;
// x: whether a host color texture is bound (else the color is white: the composite shows AO).
// One of two constant buffers, chosen per frame, so recording writes nothing to the queue.
@group(0) @binding(8) var<uniform> has_color: vec4<u32>;
// Pixels whose geometry lies outside the bounds' depth range [near, far] (cleared per frame):
// their normalized depth is clamped, so they get wrong occlusion; the chain reports the count.
@group(0) @binding(9) var<storage, read_write> outside: atomic<u32>;

var<workgroup> outside_here: atomic<u32>;

// The pixel's depth. Under MSAA: background unless at least half the samples hold geometry,
// else the mean of those (the standard sample patterns are symmetric about the pixel's centre,
// so on a plane the mean is the centre's depth; the nearest sample would pull every slope
// toward the eye).
fn depth_at(p: vec2<i32>) -> f32 {
    if SAMPLES == 1u {
        return textureLoad(host_depth, p, 0);
    }
    var sum = 0.0;
    var count = 0u;
    for (var s = 0; s < i32(SAMPLES); s++) {
        let d = textureLoad(host_depth, p, s);
        if d != host.far_depth {
            sum += d;
            count += 1u;
        }
    }
    return select(host.far_depth, sum / f32(count), 2u * count >= SAMPLES);
}

fn is_background(d: f32) -> bool {
    return d == host.far_depth;
}

// The view-space point of pixel `p` at hardware depth `d`.
fn view_position(p: vec2<i32>, d: f32) -> vec3<f32> {
    let ndc = ((vec2<f32>(p) + 0.5) / host.size * 2.0 - 1.0) * vec2<f32>(1.0, -1.0);
    let v = host.inv_proj * vec4<f32>(ndc, d, 1.0);
    return v.xyz / v.w;
}

// The neighbour at `p + step` as (view position, 1), or w = 0 where it is off the image or
// background.
fn neighbour(p: vec2<i32>, step: vec2<i32>) -> vec4<f32> {
    let q = p + step;
    if any(q < vec2<i32>(0)) || any(q >= vec2<i32>(host.size)) {
        return vec4<f32>(0.0);
    }
    let d = depth_at(q);
    if is_background(d) {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(view_position(q, d), 1.0);
}

// The tangent along one image axis: the central difference where both neighbours continue the
// surface, else toward the neighbour whose depth differs least from the centre's (so a depth
// edge on one side does not tilt the normal); w = 0 without either. Continuing means the two
// depth steps differ by at most two pixel footprints or a quarter of the larger: a curved
// surface a few pixels wide bends by about one footprint per pixel, an edge jumps by many.
// (Always taking the smaller step would flatten every curved surface: its flatter side wins.)
fn tangent(p: vec2<i32>, centre: vec3<f32>, step: vec2<i32>) -> vec4<f32> {
    let ahead = neighbour(p, step);
    let behind = neighbour(p, -step);
    let step_ahead = ahead.z - centre.z;
    let step_behind = centre.z - behind.z;
    let footprint = select(-centre.z / host.f_px, 1.0 / host.f_px, host.orthographic != 0u);
    let tolerance = max(2.0 * footprint, 0.25 * max(abs(step_ahead), abs(step_behind)));
    if ahead.w > 0.0 && behind.w > 0.0 && abs(step_ahead - step_behind) <= tolerance {
        return vec4<f32>(0.5 * (ahead.xyz - behind.xyz), 1.0);
    }
    let use_ahead = ahead.w > 0.0 && (behind.w == 0.0 || abs(step_ahead) <= abs(step_behind));
    if use_ahead {
        return vec4<f32>(ahead.xyz - centre, 1.0);
    }
    if behind.w > 0.0 {
        return vec4<f32>(centre - behind.xyz, 1.0);
    }
    return vec4<f32>(0.0);
}

fn normal_at(p: vec2<i32>, centre: vec3<f32>) -> vec3<f32> {
    if NORMALS != 0u {
        var n = textureLoad(host_normals, p, 0).xyz;
        if NORMALS == 2u || NORMALS == 4u {
            n = n * 2.0 - 1.0;
        }
        if NORMALS >= 3u {
            n = (host.view_rotation * vec4<f32>(n, 0.0)).xyz;
        }
        return normalize(n);
    }
    let dx = tangent(p, centre, vec2<i32>(1, 0));
    let dy = tangent(p, centre, vec2<i32>(0, 1));
    let n = cross(dx.xyz, dy.xyz);
    // Without two tangents (an isolated pixel) the surface faces the eye.
    if dx.w == 0.0 || dy.w == 0.0 || dot(n, n) < 1e-30 {
        return gbuffer_eye_direction(centre, host.orthographic != 0u);
    }
    return normalize(n);
}

@compute @workgroup_size(8, 8)
fn nd_from_depth(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let p = vec2<i32>(id.xy);
    if all(p < vec2<i32>(host.size)) && write_pixel(p) {
        atomicAdd(&outside_here, 1u);
    }
    // One global add per workgroup, not one per pixel.
    workgroupBarrier();
    if local == 0u {
        let count = atomicLoad(&outside_here);
        if count > 0u {
            atomicAdd(&outside, count);
        }
    }
}

// Writes the G-buffer at `p`; whether its geometry lies outside the depth range (by more than
// rounding).
fn write_pixel(p: vec2<i32>) -> bool {
    var beyond = false;
    let d = depth_at(p);
    var nd = vec4<f32>(0.0, 0.0, 0.0, 1.0);
    var zoom = 0.0;
    if !is_background(d) {
        let centre = view_position(p, d);
        let ortho = host.orthographic != 0u;
        beyond = -centre.z < host.near * (1.0 - 1e-4) || -centre.z > host.far * (1.0 + 1e-4);
        nd = gbuffer_nd(centre, normal_at(p, centre), host.near, host.far, ortho);
        zoom = gbuffer_zoom(centre, host.f_px, host.zoom_unit, ortho);
    }
    textureStore(nd_out, p, nd);
    textureStore(zoom_out, p, vec4<f32>(zoom, 0.0, 0.0, 0.0));
    let color = select(vec4<f32>(1.0), textureLoad(host_color, p, 0), has_color.x != 0u);
    textureStore(color_out, p, vec4<f32>(color.rgb, 1.0));
    textureStore(specular_out, p, vec4<f32>(0.0));
    return beyond;
}
