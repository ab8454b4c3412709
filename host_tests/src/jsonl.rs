//! The JSON Lines replay format (see README, "Replay").
//!
//! Input, one frame per line:
//! `{"camera": {"fx", "fy", "cx", "cy", "width", "height"},
//!   "motion": {"translation": [U, V, W], "rotation": [α, β, γ]} | null,
//!   "boundaries": [[[u, v], ...], ...]}`
//! (motion from the previous frame, frame-1 camera coordinates, radians).
//!
//! Output, one line per input line: the reconstruction of the pair
//! (previous line, this line), or `"first"`, or an error naming the line
//! and the field.

use roadstereo::{Camera, Frame, Motion, Pixel, Processor, Step};
use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct CameraIn {
    pub fx: f32,
    pub fy: f32,
    pub cx: f32,
    pub cy: f32,
    pub width: u16,
    pub height: u16,
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MotionIn {
    pub translation: [f32; 3],
    pub rotation: [f32; 3],
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct FrameIn {
    pub camera: CameraIn,
    #[serde(default)]
    pub motion: Option<MotionIn>,
    pub boundaries: Vec<Vec<[f32; 2]>>,
}

#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct PointOut {
    pub p1: [f32; 2],
    pub p2: Option<[f32; 2]>,
    pub xyz: Option<[f32; 3]>,
    pub z_near: Option<f32>,
    pub z_far: Option<f32>,
    pub status: String,
}

#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct LineOut {
    pub line: usize,
    pub result: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    #[serde(skip_serializing_if = "Vec::is_empty", default)]
    pub boundaries: Vec<Vec<PointOut>>,
}

/// Parse and validate one input line into a frame and its motion.
pub fn parse_line<const N: usize, const B: usize>(
    text: &str,
) -> Result<(Frame<N, B>, Option<Motion>), String> {
    let de = &mut serde_json::Deserializer::from_str(text);
    let f: FrameIn = serde_path_to_error::deserialize(de).map_err(|e| {
        let path = e.path().to_string();
        if path == "." || path == "?" {
            format!("invalid JSON: {}", e.inner())
        } else {
            format!("field `{path}`: {}", e.inner())
        }
    })?;
    let c = &f.camera;
    let cam = Camera::new(c.fx, c.fy, c.cx, c.cy, c.width, c.height)
        .map_err(|e| format!("field `camera`: {e}"))?;
    let motion = match &f.motion {
        None => None,
        Some(m) => Some(
            Motion::new(m.translation, m.rotation).map_err(|e| format!("field `motion`: {e}"))?,
        ),
    };
    let mut frame = Frame::new(cam);
    for (i, b) in f.boundaries.iter().enumerate() {
        let pts: Vec<Pixel> = b.iter().map(|p| Pixel::new(p[0], p[1])).collect();
        frame
            .push_boundary(&pts)
            .map_err(|e| format!("field `boundaries[{i}]`: {e}"))?;
    }
    Ok((frame, motion))
}

/// Process one input line (1-based number `line`) and describe the result.
pub fn process_line<const N: usize, const B: usize>(
    p: &mut Processor<N, B>,
    line: usize,
    text: &str,
) -> LineOut {
    let err = |e: String| LineOut {
        line,
        result: "error".into(),
        error: Some(format!("line {line}: {e}")),
        boundaries: Vec::new(),
    };
    let (frame, motion) = match parse_line::<N, B>(text) {
        Ok(x) => x,
        Err(e) => return err(e),
    };
    match p.process(&frame, motion.as_ref()) {
        Err(e) => err(format!("field `motion`: {e}")),
        Ok(Step::First) => LineOut {
            line,
            result: "first".into(),
            error: None,
            boundaries: Vec::new(),
        },
        Ok(Step::Structure(s)) => LineOut {
            line,
            result: "structure".into(),
            error: None,
            boundaries: s
                .boundaries()
                .iter()
                .map(|b| {
                    b.points()
                        .iter()
                        .map(|r| PointOut {
                            p1: [r.pixel1().u, r.pixel1().v],
                            p2: r.pixel2().map(|q| [q.u, q.v]),
                            xyz: s.point(r),
                            z_near: r.interval().map(|i| i.z_near),
                            z_far: r.interval().map(|i| i.z_far),
                            status: r.status().name().into(),
                        })
                        .collect()
                })
                .collect(),
        },
    }
}
