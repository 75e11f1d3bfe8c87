// Shared by every Dupin shader (prepended by `gpu_mesh::shader`): the vertex interface and
// projection, the two-sided normal and the gamma encoding for non-sRGB targets.

struct VsIn {
    @location(0) pos: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) color: vec3<f32>,
};

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) color: vec3<f32>,
};

// A vertex projected by `view_proj`, with its world position and normal, coloured `color`.
fn project(v: VsIn, view_proj: mat4x4<f32>, color: vec3<f32>) -> VsOut {
    var o: VsOut;
    o.clip = view_proj * vec4<f32>(v.pos, 1.0);
    o.world = v.pos;
    o.normal = v.normal;
    o.color = color;
    return o;
}

// The unit normal of the side facing the viewer at `eye`, whatever the winding.
fn facing_normal(i: VsOut, eye: vec3<f32>) -> vec3<f32> {
    let n = normalize(i.normal);
    return select(n, -n, dot(n, eye - i.world) < 0.0);
}

// `c` as written to the target: gamma-encoded when `gamma` is 1 (non-sRGB target).
fn encode_rgba(c: vec3<f32>, a: f32, gamma: f32) -> vec4<f32> {
    let g = pow(clamp(c, vec3<f32>(0.0), vec3<f32>(1.0)), vec3<f32>(1.0 / 2.2));
    return vec4<f32>(mix(c, g, gamma), a);
}
