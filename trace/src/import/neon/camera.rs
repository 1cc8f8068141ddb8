//! Neon's scene camera: the pinhole intrinsics and OpenCV "rational" lens distortion
//! (k1, k2, p1, p2, k3, k4, k5, k6) that turn a gaze point in scene-image pixels into a
//! direction, read from the recording's `calibration.bin`.
//!
//! `calibration.bin` starts with a version byte, the 6-byte module serial, then the scene
//! camera's 3x3 camera matrix (row-major) and its 8 distortion coefficients as little-endian
//! `f64`s (bytes 7..143); the eye cameras' calibrations follow and are not read.

use glam::DVec3;

use crate::import::RecordingError;

/// Where the scene camera matrix starts in `calibration.bin`.
const MATRIX_OFFSET: usize = 7;
/// Bytes of `calibration.bin` read: version, serial, matrix, distortion.
const CALIBRATION_BYTES: usize = MATRIX_OFFSET + 9 * 8 + 8 * 8;

/// A scene camera model: pixel coordinates to directions in the camera frame (OpenCV axes:
/// +x right, +y down, +z forward).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneCamera {
    /// Focal length along x, pixels.
    pub fx: f64,
    /// Focal length along y, pixels.
    pub fy: f64,
    /// Principal point x, pixels.
    pub cx: f64,
    /// Principal point y, pixels.
    pub cy: f64,
    /// Distortion coefficients k1, k2, p1, p2, k3, k4, k5, k6 (OpenCV's rational model).
    pub distortion: [f64; 8],
}

impl SceneCamera {
    /// The nominal Neon scene camera, used when a recording has no `calibration.bin`:
    /// 1600x1200 pixels, principal point at the centre, focal length 891 pixels, and no
    /// lens distortion. Without the real distortion, directions are off by several degrees
    /// toward the image edges.
    pub const NOMINAL: SceneCamera = SceneCamera {
        fx: 891.0,
        fy: 891.0,
        cx: 800.0,
        cy: 600.0,
        distortion: [0.0; 8],
    };

    /// Reads the scene camera from the bytes of `calibration.bin` (named `file` in messages).
    pub fn from_calibration(bytes: &[u8], file: &str) -> Result<SceneCamera, RecordingError> {
        if bytes.len() < CALIBRATION_BYTES {
            return Err(RecordingError::Truncated {
                file: file.to_owned(),
                bytes: bytes.len() as u64,
                record_bytes: CALIBRATION_BYTES,
            });
        }
        let f = |i: usize| {
            let at = MATRIX_OFFSET + 8 * i;
            let mut b = [0u8; 8];
            b.copy_from_slice(&bytes[at..at + 8]);
            f64::from_le_bytes(b)
        };
        let k: [f64; 9] = std::array::from_fn(f);
        let distortion: [f64; 8] = std::array::from_fn(|i| f(9 + i));
        let camera = SceneCamera {
            fx: k[0],
            fy: k[4],
            cx: k[2],
            cy: k[5],
            distortion,
        };
        let sane = k.iter().chain(&distortion).all(|v| v.is_finite())
            && camera.fx > 0.0
            && camera.fy > 0.0
            && (k[8] - 1.0).abs() < 1e-9
            && k[1] == 0.0
            && k[3] == 0.0
            && k[6] == 0.0
            && k[7] == 0.0;
        if !sane {
            return Err(RecordingError::BadValue {
                file: file.to_owned(),
                at: format!("bytes {MATRIX_OFFSET}..{}", MATRIX_OFFSET + 72),
                field: "scene_camera_matrix".to_owned(),
                found: format!("{k:?}"),
                expected: "a camera matrix [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] with positive focal lengths",
            });
        }
        Ok(camera)
    }

    /// Applies the lens distortion to a point on the normalised image plane (z = 1).
    fn distort(&self, x: f64, y: f64) -> (f64, f64) {
        let [k1, k2, p1, p2, k3, k4, k5, k6] = self.distortion;
        let r2 = x * x + y * y;
        let radial =
            (1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))) / (1.0 + r2 * (k4 + r2 * (k5 + r2 * k6)));
        (
            x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
            y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y,
        )
    }

    /// The pixel a camera-frame direction (z > 0) lands on.
    pub fn project(&self, direction: DVec3) -> Option<[f64; 2]> {
        if direction.z <= 0.0 {
            return None;
        }
        let (x, y) = self.distort(direction.x / direction.z, direction.y / direction.z);
        Some([self.fx * x + self.cx, self.fy * y + self.cy])
    }

    /// The unit camera-frame direction of pixel `(u, v)`; `None` when the pixel is not
    /// finite or lies where the distortion model cannot be inverted (past the radius where
    /// the distortion folds back).
    pub fn direction(&self, u: f64, v: f64) -> Option<DVec3> {
        let (x0, y0) = ((u - self.cx) / self.fx, (v - self.cy) / self.fy);
        if !(x0.is_finite() && y0.is_finite()) {
            return None;
        }
        // Newton's method on distort(x, y) = (x0, y0), with a finite-difference Jacobian,
        // from the distorted point itself.
        let (mut x, mut y) = (x0, y0);
        for _ in 0..30 {
            let (fx, fy) = self.distort(x, y);
            let (ex, ey) = (fx - x0, fy - y0);
            if ex.abs() < 1e-12 && ey.abs() < 1e-12 {
                break;
            }
            let h = 1e-7;
            let (ax, ay) = self.distort(x + h, y);
            let (bx, by) = self.distort(x, y + h);
            let (j11, j21, j12, j22) = ((ax - fx) / h, (ay - fy) / h, (bx - fx) / h, (by - fy) / h);
            let det = j11 * j22 - j12 * j21;
            if !det.is_finite() || det.abs() < 1e-12 {
                return None;
            }
            x -= (j22 * ex - j12 * ey) / det;
            y -= (j11 * ey - j21 * ex) / det;
            if !(x.is_finite() && y.is_finite()) {
                return None;
            }
        }
        let (xd, yd) = self.distort(x, y);
        // Within a hundredth of a pixel.
        let tolerance = 0.01 / self.fx.max(self.fy);
        if (xd - x0).abs() > tolerance || (yd - y0).abs() > tolerance {
            return None;
        }
        DVec3::new(x, y, 1.0).try_normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Coefficients of the size a wide-angle scene camera has.
    pub(crate) const WIDE: SceneCamera = SceneCamera {
        fx: 892.5,
        fy: 891.7,
        cx: 812.3,
        cy: 597.6,
        distortion: [-0.05, 0.02, 4e-4, -3e-4, 0.0, 0.1, 0.01, 0.0],
    };

    #[test]
    fn directions_invert_projection_across_the_image() {
        for u in (0..=1600).step_by(200) {
            for v in (0..=1200).step_by(200) {
                let (u, v) = (f64::from(u), f64::from(v));
                let d = WIDE.direction(u, v).unwrap();
                let [pu, pv] = WIDE.project(d).unwrap();
                assert!(
                    (pu - u).abs() < 0.02 && (pv - v).abs() < 0.02,
                    "{u},{v} -> {pu},{pv}"
                );
            }
        }
        let centre = WIDE.direction(WIDE.cx, WIDE.cy).unwrap();
        assert!(centre.abs_diff_eq(DVec3::Z, 1e-12));
        assert_eq!(WIDE.direction(f64::NAN, 0.0), None);
    }

    #[test]
    fn calibration_bytes_are_read_and_checked() {
        let mut bytes = vec![1u8; 7];
        let k = [WIDE.fx, 0.0, WIDE.cx, 0.0, WIDE.fy, WIDE.cy, 0.0, 0.0, 1.0];
        for v in k.iter().chain(&WIDE.distortion) {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        bytes.extend_from_slice(&[0u8; 100]);
        assert_eq!(
            SceneCamera::from_calibration(&bytes, "c.bin").unwrap(),
            WIDE
        );
        let e = SceneCamera::from_calibration(&bytes[..100], "c.bin").unwrap_err();
        assert!(e.to_string().starts_with("c.bin: 100 bytes"), "{e}");
        bytes[7..15].copy_from_slice(&(-1.0f64).to_le_bytes());
        let e = SceneCamera::from_calibration(&bytes, "c.bin").unwrap_err();
        assert!(e.to_string().contains("scene_camera_matrix"), "{e}");
    }
}
