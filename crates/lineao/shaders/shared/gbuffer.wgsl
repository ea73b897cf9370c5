// Writing the G-buffer of docs/reference.md from any shader: the functions lineao's own geometry
// passes use, and that a host renderer can include to write the ND map and zoom map itself
// (`lineao::shader::GBUFFER_WGSL`). All positions and normals are in view space (camera at the
// origin looking down −z).

// The direction C from a surface point toward the eye: −p (orthographic: the eye is at
// infinity along +z).
fn gbuffer_eye_direction(view_pos: vec3<f32>, orthographic: bool) -> vec3<f32> {
    return select(normalize(-view_pos), vec3<f32>(0.0, 0.0, 1.0), orthographic);
}

// A line's normal (LineAO §3.2): n = (T × C) × T, perpendicular to the unit tangent T in the
// plane of T and C, facing the eye (C itself where T runs along the view ray).
fn gbuffer_line_normal(t: vec3<f32>, c: vec3<f32>) -> vec3<f32> {
    var n = cross(cross(t, c), t);
    n = select(c, normalize(n), dot(n, n) > 1e-12);
    return select(n, -n, dot(n, c) < 0.0);
}

// Normalized linear depth: (−z_view − near) / (far − near), clamped to [0, 1] (docs/reference.md
// "Scene depth range").
fn gbuffer_depth(view_pos: vec3<f32>, near: f32, far: f32) -> f32 {
    return clamp((-view_pos.z - near) / (far - near), 0.0, 1.0);
}

// The ND map's texel: the unit normal `n` turned toward the eye, and normalized linear depth.
fn gbuffer_nd(view_pos: vec3<f32>, n: vec3<f32>, near: f32, far: f32, orthographic: bool) -> vec4<f32> {
    let c = gbuffer_eye_direction(view_pos, orthographic);
    return vec4<f32>(select(n, -n, dot(n, c) < 0.0), gbuffer_depth(view_pos, near, far));
}

// The zoom map's texel z(P): pixels per `zoom_unit` world units at the point's depth, for a
// focal length of `f_px` pixels (orthographic: pixels per world unit).
fn gbuffer_zoom(view_pos: vec3<f32>, f_px: f32, zoom_unit: f32, orthographic: bool) -> f32 {
    return select(f_px * zoom_unit / -view_pos.z, f_px * zoom_unit, orthographic);
}
