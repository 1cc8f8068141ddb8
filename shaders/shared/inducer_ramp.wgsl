// The inducer's distance and ramp (METHOD.md section 1, eq. 2 and 4), shared by the rows pass
// of the distance transform (shaders/inducer_distance.wgsl, which writes the gain) and the
// distance field's pass for a read back (shaders/inducer_field.wgsl). The CPU twins are in
// render/src/floor/reference.rs.

// Distance from a lit texel to the shadow edge, metres, given the offset (texels) to its
// nearest shadow texel and the floor metres per texel along x and y: the edge is taken
// halfway between that texel's centre and its lit neighbour's, i.e. half a texel short of the
// shadow texel's centre along the offset (`edge_distance_m` on the CPU).
fn edge_distance_m(offset: vec2<f32>, texel_m: vec2<f32>) -> f32 {
    let texels = length(offset);
    return length(offset * texel_m) * (1.0 - 0.5 / texels);
}

// eq. 2: alpha(d) = (D - d) / D for 0 <= d < D, 0 beyond D and inside the shadow (d < 0).
fn ramp(d_m: f32, width_m: f32) -> f32 {
    if d_m < 0.0 || d_m >= width_m {
        return 0.0;
    }
    return (width_m - d_m) / width_m;
}
