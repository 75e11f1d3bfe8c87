// Lit mesh and flat lines (after vertex_io.wgsl). Two-sided Blinn-Phong with a camera-attached key light and a fill, so
// panels read clearly from any orbit angle.

struct Uniforms {
    view_proj: mat4x4<f32>,
    eye: vec4<f32>,
    key_dir: vec4<f32>,
    base_color: vec4<f32>,
    // x: 1 to gamma-encode in the shader (non-sRGB target), y: 1 to use vertex colours.
    flags: vec4<f32>,
};

@group(0) @binding(0) var<uniform> u: Uniforms;

@vertex
fn vs_main(v: VsIn) -> VsOut {
    return project(v, u.view_proj, mix(u.base_color.rgb, v.color, u.flags.y));
}

// Edges are drawn over the faces they bound. Moving each line vertex along its ray to the eye
// (0.2% of its distance) leaves it where it is on screen but in front of its own faces at any
// slope, where a constant depth bias loses at oblique views and dashes the line; a surface
// further in front still hides it.
// Line vertices carry a position only (`POSITION_LAYOUT`); their colour is `base_color`.
@vertex
fn vs_line(@location(0) pos: vec3<f32>) -> VsOut {
    var v: VsIn;
    v.pos = mix(pos, u.eye.xyz, 0.002);
    v.normal = vec3<f32>(0.0, 0.0, 1.0);
    return project(v, u.view_proj, u.base_color.rgb);
}

fn encode(c: vec3<f32>) -> vec4<f32> {
    return encode_rgba(c, 1.0, u.flags.x);
}

@fragment
fn fs_main(i: VsOut) -> @location(0) vec4<f32> {
    let view = normalize(u.eye.xyz - i.world);
    // Two-sided: light the side the viewer sees.
    let n = facing_normal(i, u.eye.xyz);
    let key = normalize(u.key_dir.xyz);
    let fill = normalize(vec3<f32>(-key.x, 0.5, -key.z));
    let diffuse = max(dot(n, key), 0.0) * 0.75 + max(dot(n, fill), 0.0) * 0.25;
    let h = normalize(key + view);
    let spec = pow(max(dot(n, h), 0.0), 48.0) * 0.25;
    let ambient = 0.18;
    let c = i.color * (ambient + diffuse) + vec3<f32>(spec);
    return encode(c);
}

@fragment
fn fs_line(i: VsOut) -> @location(0) vec4<f32> {
    return encode(i.color);
}
