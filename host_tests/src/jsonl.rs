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
//!
//! Exactly the documented format is accepted: one JSON object per line
//! (nothing but whitespace after it), `camera` and `motion` as objects
//! (not arrays of their values, which serde's derive would also take),
//! UTF-8 text (a line that is not is an error naming it, and the next line
//! is read as usual).

use std::io::{BufRead, Write};
use std::marker::PhantomData;

use roadstereo::{Camera, Frame, Motion, Pixel, Processor, Step};
use serde::de::{self, Deserializer, MapAccess, Visitor};
use serde::{Deserialize, Serialize};

/// Deserialises a `T` only from a JSON object: the derive for a struct
/// also accepts a sequence of its fields' values, which the format does
/// not allow. The object's entries go to `T`'s own `Deserialize`, so the
/// field paths of errors are kept.
struct ObjectOnly<T>(PhantomData<T>);

impl<'de, T: Deserialize<'de>> Visitor<'de> for ObjectOnly<T> {
    type Value = T;
    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("a JSON object")
    }
    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<T, A::Error> {
        T::deserialize(de::value::MapAccessDeserializer::new(map))
    }
}

/// `deserialize_with` for a struct field that must be a JSON object.
fn object<'de, D: Deserializer<'de>, T: Deserialize<'de>>(d: D) -> Result<T, D::Error> {
    d.deserialize_map(ObjectOnly(PhantomData))
}

/// `deserialize_with` for an optional struct field: `null` or an object.
fn optional_object<'de, D: Deserializer<'de>, T: Deserialize<'de>>(
    d: D,
) -> Result<Option<T>, D::Error> {
    struct OptionalObject<T>(PhantomData<T>);
    impl<'de, T: Deserialize<'de>> Visitor<'de> for OptionalObject<T> {
        type Value = Option<T>;
        fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            f.write_str("null or a JSON object")
        }
        fn visit_none<E: de::Error>(self) -> Result<Option<T>, E> {
            Ok(None)
        }
        fn visit_unit<E: de::Error>(self) -> Result<Option<T>, E> {
            Ok(None)
        }
        fn visit_some<D: Deserializer<'de>>(self, d: D) -> Result<Option<T>, D::Error> {
            object(d).map(Some)
        }
    }
    d.deserialize_option(OptionalObject(PhantomData))
}

/// A whole input line: a [`FrameIn`] object.
struct LineIn(FrameIn);

impl<'de> Deserialize<'de> for LineIn {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        object(d).map(LineIn)
    }
}

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
    #[serde(deserialize_with = "object")]
    pub camera: CameraIn,
    #[serde(default, deserialize_with = "optional_object")]
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
    let LineIn(f) = serde_path_to_error::deserialize(&mut *de).map_err(|e| {
        let path = e.path().to_string();
        if path == "." || path == "?" {
            format!("invalid JSON: {}", e.inner())
        } else {
            format!("field `{path}`: {}", e.inner())
        }
    })?;
    // Nothing but whitespace may follow the object (a second object or any
    // other text is not part of the format). The error's column is that of
    // the first byte after the whitespace.
    de.end().map_err(|e| {
        let col = e.column();
        let what = match text.as_bytes().get(col.saturating_sub(1)) {
            Some(b'{') => "a second JSON object",
            _ => "text",
        };
        format!("{what} after the frame object at column {col} (one frame object per line)")
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
        // (An empty list: a boundary the detector lost, `push_absent`.)
        if pts.is_empty() {
            frame.push_absent()
        } else {
            frame.push_boundary(&pts)
        }
        .map_err(|e| format!("field `boundaries[{i}]`: {e}"))?;
    }
    Ok((frame, motion))
}

/// Process one input line given as bytes (1-based number `line`, without
/// its line ending): `None` for a blank line, an error naming the line for
/// bytes that are not UTF-8, otherwise [`process_line`].
pub fn process_bytes<const N: usize, const B: usize>(
    p: &mut Processor<N, B>,
    line: usize,
    bytes: &[u8],
) -> Option<LineOut> {
    let text = match std::str::from_utf8(bytes) {
        Ok(t) => t,
        Err(e) => {
            return Some(LineOut {
                line,
                result: "error".into(),
                error: Some(format!(
                    "line {line}: invalid UTF-8 at byte {} of the line",
                    e.valid_up_to()
                )),
                boundaries: Vec::new(),
            })
        }
    };
    (!text.trim().is_empty()).then(|| process_line(p, line, text))
}

/// What [`replay`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Replayed {
    /// Lines read (blank ones included: they keep the numbering).
    pub lines: usize,
    /// Lines rejected, each with an error line in the output.
    pub errors: usize,
}

/// The replay tool's loop: every line of `input` (read as bytes, split at
/// `\n`, a trailing `\r` dropped) through [`process_bytes`], one output
/// line each (blank lines give none), `on_error` told of each rejected
/// line. `Err` only when reading or writing fails, naming the line.
pub fn replay<const N: usize, const B: usize>(
    p: &mut Processor<N, B>,
    mut input: impl BufRead,
    mut output: impl Write,
    mut on_error: impl FnMut(&str),
) -> Result<Replayed, String> {
    let mut done = Replayed {
        lines: 0,
        errors: 0,
    };
    let mut buf = Vec::new();
    loop {
        buf.clear();
        let line = done.lines + 1;
        let n = input
            .read_until(b'\n', &mut buf)
            .map_err(|e| format!("read error at line {line}: {e}"))?;
        if n == 0 {
            return Ok(done);
        }
        done.lines = line;
        let mut bytes = buf.as_slice();
        bytes = bytes.strip_suffix(b"\n").unwrap_or(bytes);
        bytes = bytes.strip_suffix(b"\r").unwrap_or(bytes);
        let Some(out) = process_bytes(p, line, bytes) else {
            continue;
        };
        if let Some(e) = &out.error {
            on_error(e);
            done.errors += 1;
        }
        let text = serde_json::to_string(&out).map_err(|e| format!("line {line}: {e}"))?;
        writeln!(output, "{text}").map_err(|e| format!("write error at line {line}: {e}"))?;
    }
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
