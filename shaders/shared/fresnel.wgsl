// Shared by the shaders that name it in a `// #include shared/fresnel.wgsl` line (render/build.rs
// appends it to their source).

// Exact Fresnel reflectance for unpolarised light (twin of optics/src/optics.rs
// fresnel_reflectance): cos_i on the incident side, eta = n_incident / n_transmitted.
fn fresnel_exact(cos_incident: f32, eta: f32) -> f32 {
    let cos_i = clamp(cos_incident, 0.0, 1.0);
    let sin_t2 = eta * eta * (1.0 - cos_i * cos_i);
    if sin_t2 >= 1.0 {
        return 1.0;
    }
    let cos_t = sqrt(1.0 - sin_t2);
    let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return clamp(0.5 * (rs * rs + rp * rp), 0.0, 1.0);
}
