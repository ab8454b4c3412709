//! Pinhole camera intrinsics and pixel ↔ normalised coordinates.
//!
//! Conventions (as in the paper, Sec. 2): camera axes `x` right, `y` down,
//! `z` forward (along the optical axis). Pixel coordinates `(u, v)`: `u` is
//! the column (grows to the right), `v` the row (grows downwards), pixel
//! centres at integer coordinates, `(0, 0)` the centre of the top-left pixel.
//! A pixel maps to normalised image coordinates `x = (u - cx)/fx`,
//! `y = (v - cy)/fy` (eq. 2.1 with `f = 1`), i.e. to the ray `(x, y, 1)`.

use core::fmt;

/// A point in the image, in pixels (`u` column, `v` row).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Pixel {
    /// Column coordinate, pixels, growing to the right.
    pub u: f32,
    /// Row coordinate, pixels, growing downwards.
    pub v: f32,
}

impl Pixel {
    /// A pixel position.
    ///
    /// ```
    /// let p = roadstereo::Pixel::new(256.0, 300.5);
    /// assert_eq!(p.v, 300.5);
    /// ```
    pub const fn new(u: f32, v: f32) -> Self {
        Self { u, v }
    }

    pub(crate) fn arr(self) -> [f32; 2] {
        [self.u, self.v]
    }
}

/// How far outside the pixel-centre grid a boundary point may lie, in pixels.
///
/// A sub-pixel detector may report a point up to one pixel beyond the
/// outermost pixel centre: `u` in `[-1, width]`, `v` in `[-1, height]`.
pub const IMAGE_MARGIN_PX: f32 = 1.0;

/// Largest accepted image side, pixels.
pub const MAX_IMAGE_SIDE: u16 = 16384;

/// Why a camera was rejected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum CameraError {
    /// A parameter is NaN or infinite.
    NotFinite,
    /// A focal length is not in `[1, 1e5]` pixels.
    FocalLength,
    /// The principal point is outside the image.
    PrincipalPoint,
    /// Width or height is below 2 or above [`MAX_IMAGE_SIDE`].
    ImageSize,
}

impl core::error::Error for CameraError {}

impl fmt::Display for CameraError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::NotFinite => "camera parameter is NaN or infinite",
            Self::FocalLength => "focal length outside [1, 1e5] px",
            Self::PrincipalPoint => "principal point outside the image",
            Self::ImageSize => "image width/height outside [2, 16384] px",
        })
    }
}

/// Validated pinhole intrinsics: focal lengths `fx`, `fy` (pixels), principal
/// point `(cx, cy)` (pixels), image size. Built only by [`Camera::new`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Camera {
    fx: f32,
    fy: f32,
    cx: f32,
    cy: f32,
    width: u16,
    height: u16,
}

impl Camera {
    /// A valid stand-in used before any frame has been seen.
    pub(crate) const PLACEHOLDER: Camera = Camera {
        fx: 1.0,
        fy: 1.0,
        cx: 0.0,
        cy: 0.0,
        width: 2,
        height: 2,
    };

    /// Checked constructor: finite values, focal lengths in `[1, 1e5]` px,
    /// image sides in `[2, 16384]` px, principal point inside the image
    /// (`0 <= cx <= width - 1`, `0 <= cy <= height - 1`).
    ///
    /// ```
    /// use roadstereo::{Camera, CameraError};
    /// // The paper's simulated camera (Sec. 3): 512 x 480, f = 800 px.
    /// let cam = Camera::new(800.0, 800.0, 255.5, 239.5, 512, 480)?;
    /// assert_eq!(cam.width(), 512);
    /// assert_eq!(Camera::new(f32::NAN, 800.0, 255.5, 239.5, 512, 480), Err(CameraError::NotFinite));
    /// # Ok::<(), CameraError>(())
    /// ```
    ///
    /// `const`, so a camera (and a [`crate::Frame`] of it) can be built at
    /// compile time, e.g. in a `static`:
    ///
    /// ```
    /// use roadstereo::{Camera, Frame};
    /// const CAM: Camera = match Camera::new(800.0, 800.0, 255.5, 239.5, 512, 480) {
    ///     Ok(c) => c,
    ///     Err(_) => panic!("a valid camera"),
    /// };
    /// static FRAME: Frame<64, 2> = Frame::new(CAM);
    /// assert_eq!(FRAME.camera().width(), 512);
    /// ```
    pub const fn new(
        fx: f32,
        fy: f32,
        cx: f32,
        cy: f32,
        width: u16,
        height: u16,
    ) -> Result<Self, CameraError> {
        if !(fx.is_finite() && fy.is_finite() && cx.is_finite() && cy.is_finite()) {
            return Err(CameraError::NotFinite);
        }
        if width < 2 || width > MAX_IMAGE_SIDE || height < 2 || height > MAX_IMAGE_SIDE {
            return Err(CameraError::ImageSize);
        }
        if !(fx >= 1.0 && fx <= 1.0e5 && fy >= 1.0 && fy <= 1.0e5) {
            return Err(CameraError::FocalLength);
        }
        // (Exact: a `u16` is an `f32` exactly.)
        let (w, h) = (width as f32, height as f32);
        if !(cx >= 0.0 && cx <= w - 1.0 && cy >= 0.0 && cy <= h - 1.0) {
            return Err(CameraError::PrincipalPoint);
        }
        Ok(Self {
            fx,
            fy,
            cx,
            cy,
            width,
            height,
        })
    }

    /// Horizontal focal length, pixels.
    pub fn fx(&self) -> f32 {
        self.fx
    }
    /// Vertical focal length, pixels.
    pub fn fy(&self) -> f32 {
        self.fy
    }
    /// Principal point column, pixels.
    pub fn cx(&self) -> f32 {
        self.cx
    }
    /// Principal point row, pixels.
    pub fn cy(&self) -> f32 {
        self.cy
    }
    /// Image width, pixels.
    pub fn width(&self) -> u16 {
        self.width
    }
    /// Image height, pixels.
    pub fn height(&self) -> u16 {
        self.height
    }

    /// Pixel → normalised image coordinates `[x, y]` (the ray `(x, y, 1)`).
    ///
    /// ```
    /// # use roadstereo::{Camera, Pixel};
    /// let cam = Camera::new(800.0, 800.0, 256.0, 240.0, 512, 480).unwrap();
    /// assert_eq!(cam.normalise(Pixel::new(656.0, 240.0)), [0.5, 0.0]);
    /// ```
    pub fn normalise(&self, p: Pixel) -> [f32; 2] {
        [(p.u - self.cx) / self.fx, (p.v - self.cy) / self.fy]
    }

    /// Normalised image coordinates → pixel.
    ///
    /// ```
    /// # use roadstereo::{Camera, Pixel};
    /// let cam = Camera::new(800.0, 800.0, 256.0, 240.0, 512, 480).unwrap();
    /// assert_eq!(cam.pixel(0.5, 0.0), Pixel::new(656.0, 240.0));
    /// ```
    pub fn pixel(&self, x: f32, y: f32) -> Pixel {
        Pixel::new(self.cx + self.fx * x, self.cy + self.fy * y)
    }

    /// Whether `p` is finite and inside the image extended by [`IMAGE_MARGIN_PX`].
    pub fn contains(&self, p: Pixel) -> bool {
        let m = IMAGE_MARGIN_PX;
        p.u.is_finite()
            && p.v.is_finite()
            && (-m..=f32::from(self.width) - 1.0 + m).contains(&p.u)
            && (-m..=f32::from(self.height) - 1.0 + m).contains(&p.v)
    }

    /// The square of the largest distance, pixels, from the principal
    /// point to any point the image (with its margin) can hold.
    pub(crate) fn reach2(&self) -> f32 {
        let [dx, dy] = self.reach_uv();
        dx * dx + dy * dy
    }

    /// The largest `|u − c_x|` and `|v − c_y|`, pixels, of any point the
    /// image (with its margin) can hold.
    pub(crate) fn reach_uv(&self) -> [f32; 2] {
        let m = IMAGE_MARGIN_PX;
        [
            crate::math::fmax(self.cx + m, f32::from(self.width) - 1.0 + m - self.cx),
            crate::math::fmax(self.cy + m, f32::from(self.height) - 1.0 + m - self.cy),
        ]
    }
}
