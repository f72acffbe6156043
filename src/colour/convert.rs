//! Colour conversions: CIE XYZ and linear sRGB (IEC 61966-2-1), CIE XYZ to CIELAB (CIE
//! 015:2018), and the CIEDE2000 colour difference that every perceptual budget is stated in.

use super::data;

fn mat_vec(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [
        m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
        m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
        m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
    ]
}

/// CIE XYZ -> linear sRGB (IEC 61966-2-1 matrix, D65 white).
pub fn xyz_to_linear_srgb(xyz: [f64; 3]) -> [f64; 3] {
    mat_vec(&data::XYZ_TO_SRGB, xyz)
}

/// Linear sRGB -> CIE XYZ (exact inverse of [`xyz_to_linear_srgb`]).
pub fn linear_srgb_to_xyz(rgb: [f64; 3]) -> [f64; 3] {
    mat_vec(&data::SRGB_TO_XYZ, rgb)
}

/// CIE XYZ -> CIELAB (CIE 015:2018) relative to the white `white` (same scale as `xyz`).
pub fn xyz_to_lab(xyz: [f64; 3], white: [f64; 3]) -> [f64; 3] {
    const DELTA: f64 = 6.0 / 29.0;
    fn f(t: f64) -> f64 {
        if t > DELTA * DELTA * DELTA {
            t.cbrt()
        } else {
            t / (3.0 * DELTA * DELTA) + 4.0 / 29.0
        }
    }
    let fx = f(xyz[0] / white[0]);
    let fy = f(xyz[1] / white[1]);
    let fz = f(xyz[2] / white[2]);
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// CIEDE2000 colour difference (kL = kC = kH = 1), following the formulas of G. Sharma,
/// W. Wu, E. N. Dalal, "The CIEDE2000 color-difference formula: implementation notes,
/// supplementary test data, and mathematical observations", Color Res. Appl. 30 (2005) 21-30.
pub fn ciede2000(lab1: [f64; 3], lab2: [f64; 3]) -> f64 {
    let [l1, a1, b1] = lab1;
    let [l2, a2, b2] = lab2;
    let pow7 = |x: f64| x.powi(7);
    let p25_7 = pow7(25.0);
    // (2)-(6)
    let c1 = a1.hypot(b1);
    let c2 = a2.hypot(b2);
    let c_bar = 0.5 * (c1 + c2);
    let g = 0.5 * (1.0 - (pow7(c_bar) / (pow7(c_bar) + p25_7)).sqrt());
    let a1p = (1.0 + g) * a1;
    let a2p = (1.0 + g) * a2;
    let c1p = a1p.hypot(b1);
    let c2p = a2p.hypot(b2);
    let hue = |b: f64, ap: f64| {
        if b == 0.0 && ap == 0.0 {
            0.0
        } else {
            let h = b.atan2(ap).to_degrees();
            if h < 0.0 {
                h + 360.0
            } else {
                h
            }
        }
    };
    let h1p = hue(b1, a1p);
    let h2p = hue(b2, a2p);
    // (8)-(10)
    let dl = l2 - l1;
    let dc = c2p - c1p;
    let dh = if c1p * c2p == 0.0 {
        0.0
    } else {
        let d = h2p - h1p;
        if d > 180.0 {
            d - 360.0
        } else if d < -180.0 {
            d + 360.0
        } else {
            d
        }
    };
    let dh_big = 2.0 * (c1p * c2p).sqrt() * (0.5 * dh.to_radians()).sin();
    // (12)-(22)
    let l_bar = 0.5 * (l1 + l2);
    let c_bar_p = 0.5 * (c1p + c2p);
    let h_bar = if c1p * c2p == 0.0 {
        h1p + h2p
    } else if (h1p - h2p).abs() <= 180.0 {
        0.5 * (h1p + h2p)
    } else if h1p + h2p < 360.0 {
        0.5 * (h1p + h2p + 360.0)
    } else {
        0.5 * (h1p + h2p - 360.0)
    };
    let cosd = |deg: f64| deg.to_radians().cos();
    let t =
        1.0 - 0.17 * cosd(h_bar - 30.0) + 0.24 * cosd(2.0 * h_bar) + 0.32 * cosd(3.0 * h_bar + 6.0)
            - 0.20 * cosd(4.0 * h_bar - 63.0);
    let d_theta = 30.0 * (-((h_bar - 275.0) / 25.0).powi(2)).exp();
    let r_c = 2.0 * (pow7(c_bar_p) / (pow7(c_bar_p) + p25_7)).sqrt();
    let l50 = (l_bar - 50.0).powi(2);
    let s_l = 1.0 + 0.015 * l50 / (20.0 + l50).sqrt();
    let s_c = 1.0 + 0.045 * c_bar_p;
    let s_h = 1.0 + 0.015 * c_bar_p * t;
    let r_t = -(2.0 * d_theta).to_radians().sin() * r_c;
    let (tl, tc, th) = (dl / s_l, dc / s_c, dh_big / s_h);
    (tl * tl + tc * tc + th * th + r_t * tc * th).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colour::weights::{white_scale, WeightSet};

    /// Sharma, Wu & Dalal (2005), Table 1: (L1, a1, b1, L2, a2, b2, ΔE00). The published ΔE00 is
    /// rounded to 4 decimals, hence the 1e-4 tolerance.
    #[test]
    fn ciede2000_sharma_test_data() {
        const PAIRS: [[f64; 7]; 34] = [
            [50.0000, 2.6772, -79.7751, 50.0000, 0.0000, -82.7485, 2.0425],
            [50.0000, 3.1571, -77.2803, 50.0000, 0.0000, -82.7485, 2.8615],
            [50.0000, 2.8361, -74.0200, 50.0000, 0.0000, -82.7485, 3.4412],
            [
                50.0000, -1.3802, -84.2814, 50.0000, 0.0000, -82.7485, 1.0000,
            ],
            [
                50.0000, -1.1848, -84.8006, 50.0000, 0.0000, -82.7485, 1.0000,
            ],
            [
                50.0000, -0.9009, -85.5211, 50.0000, 0.0000, -82.7485, 1.0000,
            ],
            [50.0000, 0.0000, 0.0000, 50.0000, -1.0000, 2.0000, 2.3669],
            [50.0000, -1.0000, 2.0000, 50.0000, 0.0000, 0.0000, 2.3669],
            [50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0009, 7.1792],
            [50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0010, 7.1792],
            [50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0011, 7.2195],
            [50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0012, 7.2195],
            [50.0000, -0.0010, 2.4900, 50.0000, 0.0009, -2.4900, 4.8045],
            [50.0000, -0.0010, 2.4900, 50.0000, 0.0010, -2.4900, 4.8045],
            [50.0000, -0.0010, 2.4900, 50.0000, 0.0011, -2.4900, 4.7461],
            [50.0000, 2.5000, 0.0000, 50.0000, 0.0000, -2.5000, 4.3065],
            [50.0000, 2.5000, 0.0000, 73.0000, 25.0000, -18.0000, 27.1492],
            [50.0000, 2.5000, 0.0000, 61.0000, -5.0000, 29.0000, 22.8977],
            [50.0000, 2.5000, 0.0000, 56.0000, -27.0000, -3.0000, 31.9030],
            [50.0000, 2.5000, 0.0000, 58.0000, 24.0000, 15.0000, 19.4535],
            [50.0000, 2.5000, 0.0000, 50.0000, 3.1736, 0.5854, 1.0000],
            [50.0000, 2.5000, 0.0000, 50.0000, 3.2972, 0.0000, 1.0000],
            [50.0000, 2.5000, 0.0000, 50.0000, 1.8634, 0.5757, 1.0000],
            [50.0000, 2.5000, 0.0000, 50.0000, 3.2592, 0.3350, 1.0000],
            [
                60.2574, -34.0099, 36.2677, 60.4626, -34.1751, 39.4387, 1.2644,
            ],
            [
                63.0109, -31.0961, -5.8663, 62.8187, -29.7946, -4.0864, 1.2630,
            ],
            [61.2901, 3.7196, -5.3901, 61.4292, 2.2480, -4.9620, 1.8731],
            [35.0831, -44.1164, 3.7933, 35.0232, -40.0716, 1.5901, 1.8645],
            [
                22.7233, 20.0904, -46.6940, 23.0331, 14.9730, -42.5619, 2.0373,
            ],
            [36.4612, 47.8580, 18.3852, 36.2715, 50.5065, 21.2231, 1.4146],
            [90.8027, -2.0831, 1.4410, 91.1528, -1.6435, 0.0447, 1.4441],
            [90.9257, -0.5406, -0.9208, 88.6381, -0.8985, -0.7239, 1.5381],
            [6.7747, -0.2908, -2.4247, 5.8714, -0.0985, -2.2286, 0.6377],
            [2.0776, 0.0795, -1.1350, 0.9033, -0.0636, -0.5514, 0.9082],
        ];
        for (i, p) in PAIRS.iter().enumerate() {
            let lab1 = [p[0], p[1], p[2]];
            let lab2 = [p[3], p[4], p[5]];
            let d12 = ciede2000(lab1, lab2);
            let d21 = ciede2000(lab2, lab1);
            assert!(
                (d12 - p[6]).abs() < 1e-4,
                "pair {}: {d12} vs {}",
                i + 1,
                p[6]
            );
            assert!((d12 - d21).abs() < 1e-12, "pair {}: not symmetric", i + 1);
        }
        assert_eq!(ciede2000([50.0, 10.0, -10.0], [50.0, 10.0, -10.0]), 0.0);
    }

    #[test]
    fn srgb_matrix_round_trip_and_white() {
        // IEC 61966-2-1:1999 published matrices
        let fwd = [
            [3.2406, -1.5372, -0.4986],
            [-0.9689, 1.8758, 0.0415],
            [0.0557, -0.2040, 1.0570],
        ];
        let inv = [
            [0.4124, 0.3576, 0.1805],
            [0.2126, 0.7152, 0.0722],
            [0.0193, 0.1192, 0.9505],
        ];
        for r in 0..3 {
            for c in 0..3 {
                assert_eq!(data::XYZ_TO_SRGB[r][c], fwd[r][c]);
                assert!((data::SRGB_TO_XYZ[r][c] - inv[r][c]).abs() < 1e-4);
            }
        }
        for v in [
            [0.2, 0.5, 0.9],
            [1.0, 1.0, 1.0],
            [-0.3, 0.7, 0.01],
            [0.95047, 1.0, 1.08883],
        ] {
            let back = linear_srgb_to_xyz(xyz_to_linear_srgb(v));
            let back2 = xyz_to_linear_srgb(linear_srgb_to_xyz(v));
            for i in 0..3 {
                assert!((back[i] - v[i]).abs() < 1e-14, "{v:?} -> {back:?}");
                assert!((back2[i] - v[i]).abs() < 1e-14, "{v:?} -> {back2:?}");
            }
        }
        // the D65 white maps to (1, 1, 1) within the 4-decimal rounding of the matrix
        let rgb = xyz_to_linear_srgb(white_scale(WeightSet::XyzD65));
        for x in rgb {
            assert!((x - 1.0).abs() < 1e-3, "{rgb:?}");
        }
        let s = white_scale(WeightSet::SrgbD65);
        for x in s {
            assert!((x - 1.0).abs() < 1e-3, "{s:?}");
        }
    }

    #[test]
    fn lab_of_white_and_ciede2000_of_flat_spectra() {
        let white = white_scale(WeightSet::XyzD65);
        let lab = xyz_to_lab(white, white);
        assert!((lab[0] - 100.0).abs() < 1e-12 && lab[1].abs() < 1e-12 && lab[2].abs() < 1e-12);
        // 18% grey: L* = 116 * 0.18^(1/3) - 16
        let grey = xyz_to_lab([0.18 * white[0], 0.18, 0.18 * white[2]], white);
        assert!((grey[0] - (116.0 * 0.18f64.cbrt() - 16.0)).abs() < 1e-12);
        // dark branch is continuous at (6/29)^3
        let t = (6.0f64 / 29.0).powi(3);
        let lo = xyz_to_lab([0.0, t * (1.0 - 1e-12), 0.0], [1.0; 3])[0];
        let hi = xyz_to_lab([0.0, t * (1.0 + 1e-12), 0.0], [1.0; 3])[0];
        assert!((lo - 8.0).abs() < 1e-9 && (hi - 8.0).abs() < 1e-9);
    }
}
