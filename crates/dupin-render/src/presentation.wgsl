// Presentation mode (after vertex_io.wgsl): metal frames (boxes with shared corners) and a ground that receive a shadow map of the frames, and glass
// panels blended over them with a Fresnel-like rim. Soft light: a sky/ground hemisphere ambient
// plus one sun whose shadow is filtered with a 3x3 percentage-closer kernel.

struct Uniforms {
    view_proj: mat4x4<f32>,
    light_view_proj: mat4x4<f32>,
    eye: vec4<f32>,
    sun: vec4<f32>,
    glass: vec4<f32>,
    metal: vec4<f32>,
    // x: 1 to gamma-encode in the shader (non-sRGB target), y: shadow map texel size.
    flags: vec4<f32>,
};

@group(0) @binding(0) var<uniform> u: Uniforms;
@group(0) @binding(1) var shadow_map: texture_depth_2d;
@group(0) @binding(2) var shadow_sampler: sampler_comparison;

@vertex
fn vs_main(v: VsIn) -> VsOut {
    return project(v, u.view_proj, v.color);
}

@vertex
fn vs_shadow(v: VsIn) -> @builtin(position) vec4<f32> {
    return u.light_view_proj * vec4<f32>(v.pos, 1.0);
}

fn encode(c: vec3<f32>, a: f32) -> vec4<f32> {
    return encode_rgba(c, a, u.flags.x);
}

// Fraction of the sun reaching `world` (1 lit, 0 shadowed), 3x3 PCF.
fn sunlight(world: vec3<f32>, n: vec3<f32>) -> f32 {
    let lp = u.light_view_proj * vec4<f32>(world + n * u.flags.z, 1.0);
    let ndc = lp.xyz / lp.w;
    let uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    let depth = ndc.z - 0.002;
    // Outside the map (most of the ground) is sunlit: skip the nine taps there.
    let inside = all(uv >= vec2<f32>(0.0)) && all(uv <= vec2<f32>(1.0)) && depth <= 1.0;
    if !inside {
        return 1.0;
    }
    var lit = 0.0;
    for (var dx = -1; dx <= 1; dx++) {
        for (var dy = -1; dy <= 1; dy++) {
            let o = vec2<f32>(f32(dx), f32(dy)) * u.flags.y;
            lit += textureSampleCompareLevel(shadow_map, shadow_sampler, uv + o, depth);
        }
    }
    return lit / 9.0;
}

fn hemisphere(n: vec3<f32>) -> vec3<f32> {
    let sky = vec3<f32>(0.36, 0.42, 0.52);
    let ground = vec3<f32>(0.16, 0.14, 0.12);
    return mix(ground, sky, n.z * 0.5 + 0.5);
}

@fragment
fn fs_metal(i: VsOut) -> @location(0) vec4<f32> {
    let view = normalize(u.eye.xyz - i.world);
    // The flat normal of the triangle from screen-space derivatives of the world position (both
    // lie in its plane): the boxes share 8 corner vertices and carry no face normals.
    let d = cross(dpdx(i.world), dpdy(i.world));
    let len = length(d);
    var n = select(view, d / len, len > 0.0);
    n = select(n, -n, dot(n, view) < 0.0);
    let sun = normalize(u.sun.xyz);
    let lit = sunlight(i.world, n);
    let h = normalize(sun + view);
    let diffuse = max(dot(n, sun), 0.0) * lit;
    let spec = pow(max(dot(n, h), 0.0), 64.0) * 0.9 * lit;
    let c = i.color * (hemisphere(n) * 0.9 + diffuse * 0.85) + vec3<f32>(spec);
    return encode(c, 1.0);
}

@fragment
fn fs_glass(i: VsOut) -> @location(0) vec4<f32> {
    let view = normalize(u.eye.xyz - i.world);
    let n = facing_normal(i, u.eye.xyz);
    let sun = normalize(u.sun.xyz);
    let lit = sunlight(i.world, n);
    let cos_v = clamp(dot(n, view), 0.0, 1.0);
    // Schlick's Fresnel term: panels seen edge-on reflect more and let less through.
    let fresnel = 0.04 + 0.96 * pow(1.0 - cos_v, 5.0);
    let h = normalize(sun + view);
    let spec = pow(max(dot(n, h), 0.0), 180.0) * 1.5 * lit;
    let sky = hemisphere(reflect(-view, n));
    let c = u.glass.rgb * i.color * (0.35 + 0.4 * max(dot(n, sun), 0.0) * lit) + sky * fresnel + vec3<f32>(spec);
    let a = clamp(u.glass.a + (1.0 - u.glass.a) * fresnel + spec, 0.0, 1.0);
    return encode(c, a);
}

@fragment
fn fs_ground(i: VsOut) -> @location(0) vec4<f32> {
    let lit = sunlight(i.world, vec3<f32>(0.0, 0.0, 1.0));
    let sun = normalize(u.sun.xyz);
    let c = i.color * (0.45 + 0.55 * max(sun.z, 0.0) * lit);
    return encode(c, 1.0);
}
