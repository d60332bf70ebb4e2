// Angles without WGSL's builtin trigonometry, whose precision Vulkan leaves loose
// (sin/cos/asin to about 2^-11 absolute): atan by a polynomial. Shared by the
// closed-form binding kernels (bind_mvc.wgsl, bind_green.wgsl).

const PI: f32 = 3.14159265358979;

// atan on [-1, 1] to about 1 ulp (Cephes atanf).
fn atan_unit(x: f32) -> f32 {
    var offset = 0.0;
    var y = x;
    if abs(x) > 0.41421356 {
        offset = sign(x) * (0.25 * PI);
        y = (abs(x) - 1.0) / (abs(x) + 1.0) * sign(x);
    }
    let z = y * y;
    return offset + ((((8.05374449538e-2 * z - 1.38776856032e-1) * z + 1.99777106478e-1) * z
        - 3.33329491539e-1) * z * y + y);
}

// The angle in [0, π] with this sine (≥ 0) and cosine.
fn angle(sine: f32, cosine: f32) -> f32 {
    if sine <= cosine {
        return atan_unit(sine / cosine);
    }
    if sine <= -cosine {
        return PI - atan_unit(sine / -cosine);
    }
    return 0.5 * PI - atan_unit(cosine / sine);
}

// atan2(y, x) in (-π, π], homogeneous in (y, x): only their ratio and signs count.
fn atan2_precise(y: f32, x: f32) -> f32 {
    let magnitude = angle(abs(y), x);
    return select(magnitude, -magnitude, y < 0.0);
}
