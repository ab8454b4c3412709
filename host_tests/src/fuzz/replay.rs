//! The replay parser and loop ([`crate::jsonl::replay`]) on JSON Lines
//! input: valid frame lines (from the frame target's generator), mutated
//! ones (cut, a byte changed, invalid UTF-8, a second object or text after
//! the object, a camera as an array, unknown fields, numbers out of range,
//! deep nesting), blank lines and CRLF endings. cargo-fuzz feeds raw
//! bytes to [`check_input`] instead.
//!
//! Oracles: no panic; `Ok` with one line counted per input line; one
//! output line per non-blank input line, numbered in order, each valid
//! JSON, every error naming its line and passed to `on_error`; every
//! depth finite inside its stick; the state untouched by rejected lines
//! (replaying only the accepted lines gives the same results); same input,
//! same output.

use crate::jsonl::{replay, LineOut};
use roadstereo::{Config, Processor};

use super::frame::{self, Call};
use super::{Outcome, Source};

const N: usize = 64;
const B: usize = 3;

/// A JSON number for an `f32` (NaN and the infinities are not JSON: a
/// string in their place, which the parser must reject).
fn num(x: f32) -> String {
    if x.is_finite() {
        format!("{x:?}")
    } else {
        format!("\"{x}\"")
    }
}

fn line_of(f: &frame::FrameIn, m: Option<&frame::MotionIn>) -> String {
    let b: Vec<String> = f
        .boundaries
        .iter()
        .map(|b| {
            let p: Vec<String> = b
                .iter()
                .map(|p| format!("[{},{}]", num(p[0]), num(p[1])))
                .collect();
            format!("[{}]", p.join(","))
        })
        .collect();
    let motion = match m {
        None => "null".to_string(),
        Some(m) => format!(
            "{{\"translation\":[{}],\"rotation\":[{}]}}",
            m.t.map(num).join(","),
            m.r.map(num).join(",")
        ),
    };
    format!(
        "{{\"camera\":{{\"fx\":{},\"fy\":{},\"cx\":{},\"cy\":{},\"width\":{},\"height\":{}}},\"motion\":{motion},\"boundaries\":[{}]}}",
        num(f.k[0]),
        num(f.k[1]),
        num(f.k[2]),
        num(f.k[3]),
        f.size.0,
        f.size.1,
        b.join(",")
    )
}

/// Draw an input.
pub fn generate(src: &mut Source) -> Vec<u8> {
    let case = frame::generate(src);
    let mut out: Vec<u8> = Vec::new();
    let mut lines: Vec<Vec<u8>> = case
        .calls
        .iter()
        .map(|c| match c {
            Call::Process(f, m) => line_of(f, m.as_ref()).into_bytes(),
            Call::AgainstKept(f, m) => line_of(f, Some(m)).into_bytes(),
            Call::Reset => Vec::new(),
        })
        .collect();
    for l in lines.iter_mut() {
        let mutate = src.below(4) == 0;
        if !mutate || l.is_empty() {
            continue;
        }
        let at = src.index(l.len() + 1);
        match src.below(12) {
            0 => l.truncate(at),
            1 => l.insert(at, src.pick(&[0xff, 0xc3, 0x80, 0xed, 0x00, b'\r'])),
            2 => {
                if let Some(b) = l.get_mut(at) {
                    *b = src.u32() as u8;
                }
            }
            3 => {
                let extra = l.clone();
                l.push(b' ');
                l.extend_from_slice(&extra);
            }
            4 => l.extend_from_slice(src.pick(&[&b" garbage"[..], b"}", b",", b" \t ", b"\"\""])),
            5 => {
                let s = String::from_utf8_lossy(l).replace("\"camera\":{\"fx\":", "\"camera\":[");
                *l = s.replacen(",\"fy\":", ",", 1).into_bytes();
            }
            6 => {
                let s = String::from_utf8_lossy(l).replacen("{", "{\"extra\":1,", 1);
                *l = s.into_bytes();
            }
            7 => {
                let s = String::from_utf8_lossy(l);
                let field = src.pick(&["\"width\":", "\"fx\":", "\"height\":"]);
                let value = src.pick(&["70000", "-1", "1e400", "-0", "1.5", "0", "65535", "null"]);
                *l = replace_value(&s, field, value).into_bytes();
            }
            8 => {
                let depth = src.pick(&[10, 127, 128, 129, 5000]);
                *l = format!("{}{}", "[".repeat(depth), "]".repeat(depth)).into_bytes();
            }
            9 => {
                *l = src
                    .pick(&[&b"null"[..], b"[]", b"{}", b"\"x\"", b"   "])
                    .to_vec()
            }
            10 => {
                let s = String::from_utf8_lossy(l).replacen("\"motion\":null,", "", 1);
                *l = s.into_bytes();
            }
            _ => l.splice(at..at, "é€😀".bytes()).for_each(drop),
        }
    }
    for l in &lines {
        out.extend_from_slice(l);
        out.extend_from_slice(if src.chance(1, 8) { b"\r\n" } else { b"\n" });
    }
    if src.chance(1, 4) {
        out.pop();
    }
    out
}

/// Replace the value after `field` (up to the next `,` or `}`).
fn replace_value(s: &str, field: &str, value: &str) -> String {
    let Some(i) = s.find(field) else {
        return s.to_string();
    };
    let start = i + field.len();
    let end = s[start..].find([',', '}']).map_or(s.len(), |j| start + j);
    format!("{}{}{}", &s[..start], value, &s[end..])
}

/// The input of `src`, as text (for a report).
pub fn describe(src: &mut Source) -> String {
    String::from_utf8_lossy(&generate(src)).into_owned()
}

/// Generate an input from `src` and check it.
pub fn run(src: &mut Source) -> Outcome {
    check_input(&generate(src))
}

fn replay_all(input: &[u8]) -> (crate::jsonl::Replayed, Vec<u8>, Vec<String>) {
    let mut p = Box::new(Processor::<N, B>::new(Config::DEFAULT));
    let mut out = Vec::new();
    let mut errors = Vec::new();
    let done = replay(&mut p, input, &mut out, |e| errors.push(e.to_string()))
        .expect("replay: reading from memory and writing to memory cannot fail");
    (done, out, errors)
}

/// Check the replay of `input` (panics on a finding).
pub fn check_input(input: &[u8]) -> Outcome {
    let (done, out, errors) = replay_all(input);
    // Lines: every `\n` ends one, and a last line without one counts.
    let lines = input.split(|&b| b == b'\n').count()
        - usize::from(input.ends_with(b"\n") || input.is_empty());
    assert_eq!(done.lines, lines, "replay: lines counted");
    let text = String::from_utf8(out.clone()).expect("replay: the output is UTF-8");
    let outs: Vec<LineOut> = text
        .lines()
        .map(|l| {
            serde_json::from_str(l)
                .unwrap_or_else(|e| panic!("replay: output line {l:?} is not JSON: {e}"))
        })
        .collect();
    let non_blank = input
        .split(|&b| b == b'\n')
        .take(lines)
        .filter(|l| {
            let l = l.strip_suffix(b"\r").unwrap_or(l);
            std::str::from_utf8(l).map_or(true, |t| !t.trim().is_empty())
        })
        .count();
    assert_eq!(
        outs.len(),
        non_blank,
        "replay: one output line per non-blank input line"
    );
    let mut last = 0;
    let mut features = 0u128;
    for o in &outs {
        assert!(
            o.line > last && o.line <= lines,
            "replay: line numbers out of order"
        );
        last = o.line;
        match (o.result.as_str(), &o.error) {
            ("error", Some(e)) => {
                features |= 1;
                assert!(
                    e.starts_with(&format!("line {}: ", o.line)),
                    "replay: error {e:?} does not name its line"
                );
                assert!(o.boundaries.is_empty());
            }
            ("first", None) => features |= 2,
            ("structure", None) => {
                features |= 4;
                for p in o.boundaries.iter().flatten() {
                    if let (Some(xyz), Some(n), Some(f)) = (p.xyz, p.z_near, p.z_far) {
                        features |= 8;
                        assert!(
                            xyz.iter().all(|x| x.is_finite()) && n <= xyz[2] && xyz[2] <= f,
                            "replay: line {}: point {p:?}",
                            o.line
                        );
                    } else {
                        assert!(p.xyz.is_none() && p.z_near.is_none() && p.z_far.is_none());
                    }
                }
            }
            (r, e) => panic!("replay: line {}: result {r:?} with error {e:?}", o.line),
        }
    }
    let n_err = outs.iter().filter(|o| o.error.is_some()).count();
    assert_eq!(done.errors, n_err, "replay: errors counted");
    assert_eq!(errors.len(), n_err, "replay: on_error calls");
    // Same input, same output.
    let (_, again, _) = replay_all(input);
    assert!(again == out, "replay: not deterministic");
    // Rejected lines leave the state untouched: the accepted lines alone
    // give the same results.
    if n_err > 0 {
        let raw: Vec<&[u8]> = input.split(|&b| b == b'\n').take(lines).collect();
        let mut kept = Vec::new();
        for o in outs.iter().filter(|o| o.error.is_none()) {
            kept.extend_from_slice(raw[o.line - 1]);
            kept.push(b'\n');
        }
        let (_, alone, _) = replay_all(&kept);
        let alone: Vec<LineOut> = String::from_utf8_lossy(&alone)
            .lines()
            .filter_map(|l| serde_json::from_str(l).ok())
            .collect();
        let accepted: Vec<&LineOut> = outs.iter().filter(|o| o.error.is_none()).collect();
        assert_eq!(
            alone.len(),
            accepted.len(),
            "replay: the accepted lines alone"
        );
        for (a, b) in accepted.iter().zip(&alone) {
            assert!(
                a.result == b.result && a.boundaries == b.boundaries,
                "replay: line {} differs when the rejected lines are left out",
                a.line
            );
        }
    }
    Outcome {
        calls: lines as u64,
        features,
        ..Outcome::default()
    }
}
