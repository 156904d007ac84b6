//! Colors for |mu| in written meshes: the viridis colormap (perceptually uniform).

/// Viridis sampled at 0, 1/8, .., 1 (sRGB in [0, 1]), interpolated linearly between.
const VIRIDIS: [[f32; 3]; 9] = [
    [0.267, 0.005, 0.329],
    [0.279, 0.175, 0.483],
    [0.230, 0.322, 0.546],
    [0.173, 0.449, 0.558],
    [0.128, 0.567, 0.551],
    [0.151, 0.682, 0.499],
    [0.369, 0.789, 0.383],
    [0.678, 0.864, 0.190],
    [0.993, 0.906, 0.144],
];

/// The viridis color of `t` clamped to [0, 1].
pub fn viridis(t: f64) -> [f32; 3] {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let x = t * (VIRIDIS.len() - 1) as f64;
    let k = (x.floor() as usize).min(VIRIDIS.len() - 2);
    let s = (x - k as f64) as f32;
    let (a, b) = (VIRIDIS[k], VIRIDIS[k + 1]);
    [
        a[0] + s * (b[0] - a[0]),
        a[1] + s * (b[1] - a[1]),
        a[2] + s * (b[2] - a[2]),
    ]
}
