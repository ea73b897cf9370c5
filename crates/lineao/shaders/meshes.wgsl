// Context surfaces: triangle meshes writing the G-buffer of docs/reference.md (color with Phong
// diffuse, the ND map with the interpolated normal turned toward the eye, zoom, specular and
// hardware depth), so that a surface shown with the tracts occludes them and is occluded.
// Two-sided: a hull seen from inside is lit like one seen from outside.
#import shared/geometry.wgsl

struct MeshVertex {
    @location(0) p: vec3<f32>,
    @location(1) n: vec3<f32>,
}

struct MeshOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) view_pos: vec3<f32>,
    @location(1) view_normal: vec3<f32>,
}

@vertex
fn vs_mesh(v: MeshVertex) -> MeshOut {
    var out: MeshOut;
    let view_pos = frame.view * vec4<f32>(v.p, 1.0);
    out.clip = frame.proj * view_pos;
    out.view_pos = view_pos.xyz;
    // The view matrix is a rotation and a translation: normals transform like directions.
    out.view_normal = (frame.view * vec4<f32>(v.n, 0.0)).xyz;
    return out;
}

fn mesh_gbuffer(in: MeshOut) -> GBuffer {
    var out: GBuffer;
    out.nd = gbuffer_nd(in.view_pos, normalize(in.view_normal), frame.near, frame.far, is_orthographic());
    let n = out.nd.xyz;
    let v = gbuffer_eye_direction(in.view_pos, is_orthographic());
    let lit = phong(n, v);
    out.color = vec4<f32>(frame.constant_color.rgb * (1.0 - lighting.kd + lighting.kd * lit.x), 1.0);
    out.zoom = gbuffer_zoom(in.view_pos, frame.f_px, frame.zoom_unit, is_orthographic());
    out.specular = lit.y;
    return out;
}

@fragment
fn fs_mesh(in: MeshOut) -> GBuffer {
    return mesh_gbuffer(in);
}

// Surfaces are not in the lines' density volume: fully visible to object-space AO.
@fragment
fn fs_mesh_octants(in: MeshOut) -> GBufferOctants {
    return with_octants(mesh_gbuffer(in), vec4<f32>(1.0), vec4<f32>(1.0));
}
