//! Spatially coherent processing order for batches of query points.
//!
//! The batch queries handle their points in the order of the Morton (Z-order) code of
//! their coordinates: 21 bits per axis of the position in the points' bounding box,
//! interleaved into a 63-bit key. Consecutive points are then close in space, so the
//! kd-tree nodes, face samples and mesh data they touch stay in cache, and the previous
//! point's face is a good start for the next search. Results are still returned in the
//! caller's order.

use nalgebra::Point3;

/// Spreads the low 21 bits of `x` so that bit `i` lands on bit `3 i`.
fn spread(x: u64) -> u64 {
    let mut x = x & 0x1F_FFFF;
    x = (x | (x << 32)) & 0x001F_0000_0000_FFFF;
    x = (x | (x << 16)) & 0x001F_0000_FF00_00FF;
    x = (x | (x << 8)) & 0x100F_00F0_0F00_F00F;
    x = (x | (x << 4)) & 0x10C3_0C30_C30C_30C3;
    x = (x | (x << 2)) & 0x1249_2492_4924_9249;
    x
}

/// The indices of `points` sorted by Morton code within their bounding box (ties keep
/// index order). Non-finite coordinates give arbitrary but valid positions in the order.
pub fn order(points: &[Point3<f64>]) -> Vec<u32> {
    let Some(first) = points.first() else {
        return Vec::new();
    };
    let (lo, hi) = points
        .iter()
        .fold((*first, *first), |(lo, hi), p| (lo.inf(p), hi.sup(p)));
    let extent = (hi - lo).amax();
    let scale = if extent > 0.0 {
        ((1u64 << 21) - 1) as f64 / extent
    } else {
        0.0
    };
    let cell = |x: f64, origin: f64| ((x - origin) * scale) as u64;
    let mut keyed: Vec<(u64, u32)> = points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let key = spread(cell(p.x, lo.x))
                | (spread(cell(p.y, lo.y)) << 1)
                | (spread(cell(p.z, lo.z)) << 2);
            (key, i as u32)
        })
        .collect();
    keyed.sort_unstable();
    keyed.into_iter().map(|(_, i)| i).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spreading_interleaves_bits() {
        assert_eq!(spread(0b1), 0b1);
        assert_eq!(spread(0b11), 0b1001);
        assert_eq!(spread(0x1F_FFFF), 0x1249_2492_4924_9249);
        // Bits above 21 are dropped.
        assert_eq!(spread(1 << 21), 0);
    }

    #[test]
    fn order_is_a_permutation_along_the_z_curve() {
        let points: Vec<Point3<f64>> = [(1.0, 1.0), (0.0, 0.0), (1.0, 0.0), (0.0, 1.0)]
            .iter()
            .map(|&(x, y)| Point3::new(x, y, 0.0))
            .collect();
        // Z order: (0,0), (1,0), (0,1), (1,1).
        assert_eq!(order(&points), vec![1, 2, 3, 0]);
        assert!(order(&[]).is_empty());
        assert_eq!(order(&[Point3::origin(); 3]).len(), 3);
    }
}
