// Shadow mask of the shadow inducer (METHOD.md section 1; render/src/inducer.rs).
//
// The object's mesh is projected from the point light onto the floor plane and rasterised
// straight into floor space: `clip_from_model` chains the model transform, the planar shadow
// projection (each vertex slides along the ray from the light until it meets the floor, as a
// homogeneous 4x4 matrix) and the map from the floor's unit square to clip space. Every
// covered texel is in shadow. For an opaque occluder this is what a depth shadow map looked
// up from the floor gives, without the map's own resolution and bias; it is exact at the
// mask's resolution. Vertices beyond the light's height get w <= 0 and are clipped away.

struct Mask {
    clip_from_model: mat4x4<f32>,
};

var<push_constant> mask: Mask;

@vertex
fn vs_main(@location(0) position: vec3<f32>) -> @builtin(position) vec4<f32> {
    return mask.clip_from_model * vec4<f32>(position, 1.0);
}

@fragment
fn fs_main() -> @location(0) vec4<f32> {
    return vec4<f32>(1.0, 0.0, 0.0, 1.0);
}
