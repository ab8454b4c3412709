//! The JSON Lines replay: good lines give the library's results, bad lines
//! give an error naming the line and the field, and processing goes on.

use host_tests::jsonl::{parse_line, process_line, replay, LineOut, Replayed};
use roadstereo::{Config, Processor, Step};

const N: usize = 64;
const B: usize = 2;

fn example() -> Vec<String> {
    let text = include_str!("../../docs/example.jsonl");
    text.lines().map(str::to_string).collect()
}

#[test]
fn replay_matches_the_library_and_survives_bad_lines() {
    let good = example();
    assert_eq!(good.len(), 2);
    // Direct use of the library.
    let mut direct = Box::new(Processor::<N, B>::new(Config::default()));
    let (f1, _) = parse_line::<N, B>(&good[0]).expect("line 1 parses");
    let (f2, m2) = parse_line::<N, B>(&good[1]).expect("line 2 parses");
    assert!(matches!(direct.process(&f1, None), Ok(Step::First)));
    assert!(matches!(
        direct.process(&f2, m2.as_ref()),
        Ok(Step::Structure(_))
    ));

    let edit = |f: &dyn Fn(&mut serde_json::Value)| {
        let mut v: serde_json::Value = serde_json::from_str(&good[1]).unwrap();
        f(&mut v);
        v.to_string()
    };
    let bad_point = edit(&|v| v["boundaries"][0][1][0] = 9999.0.into());
    let bad_motion = edit(&|v| v["motion"]["translation"][0] = f64::INFINITY.into());
    let nan_rotation = edit(&|v| v["motion"]["rotation"][1] = 4.0.into());
    let lines = [
        good[0].clone(),
        "{ this is not json".to_string(),
        good[1].replace("\"fx\"", "\"focal\""),
        bad_point,
        bad_motion,
        nan_rotation,
        good[1].clone(),
    ];
    let mut p = Box::new(Processor::<N, B>::new(Config::default()));
    let outs: Vec<LineOut> = lines
        .iter()
        .enumerate()
        .map(|(i, l)| process_line(&mut p, i + 1, l))
        .collect();
    for o in &outs {
        println!(
            "{}",
            serde_json::to_string(o)
                .unwrap()
                .chars()
                .take(160)
                .collect::<String>()
        );
    }
    assert_eq!(outs[0].result, "first");
    let err = |i: usize| outs[i].error.clone().unwrap_or_default();
    assert!(err(1).starts_with("line 2: invalid JSON"), "{}", err(1));
    assert!(
        err(2).starts_with("line 3:") && err(2).contains("focal"),
        "{}",
        err(2)
    );
    assert!(
        err(3).starts_with("line 4: field `boundaries[0]`"),
        "{}",
        err(3)
    );
    assert!(
        err(4).starts_with("line 5: field `motion.translation[0]`"),
        "{}",
        err(4)
    );
    assert!(err(5).starts_with("line 6: field `motion`"), "{}", err(5));
    assert_eq!(outs[6].result, "structure");
    // The good pair after four bad lines gives exactly the direct result.
    let s = direct.structure();
    let last = &outs[6];
    assert_eq!(last.boundaries.len(), s.boundaries().len());
    for (ob, sb) in last.boundaries.iter().zip(s.boundaries()) {
        assert_eq!(ob.len(), sb.points().len());
        for (op, sp) in ob.iter().zip(sb.points()) {
            assert_eq!(op.status, sp.status().name());
            assert_eq!(op.p2, sp.pixel2().map(|q| [q.u, q.v]));
            assert_eq!(op.xyz, s.point(sp));
            assert_eq!(op.z_near, sp.interval().map(|i| i.z_near));
        }
    }
    assert!(last.boundaries.iter().flatten().any(|p| p.status == "ok"));
}

/// `replay` over `input` (the tool's own loop): the output lines, parsed,
/// the error messages it reported and its counts.
fn run(input: &[u8]) -> (Vec<LineOut>, Vec<String>, Replayed) {
    let mut p = Box::new(Processor::<N, B>::new(Config::default()));
    let mut out = Vec::new();
    let mut errors = Vec::new();
    let done =
        replay(&mut p, input, &mut out, |e| errors.push(e.to_string())).expect("no I/O error");
    let lines = String::from_utf8(out)
        .expect("the output is UTF-8")
        .lines()
        .map(|l| serde_json::from_str(l).expect("each output line is a LineOut"))
        .collect();
    (lines, errors, done)
}

/// The example's second line processed against its first, directly
/// through the library, must equal `out` point by point.
fn assert_is_the_example_pair(out: &LineOut) {
    let good = example();
    let mut direct = Box::new(Processor::<N, B>::new(Config::default()));
    let (f1, _) = parse_line::<N, B>(&good[0]).expect("line 1 parses");
    let (f2, m2) = parse_line::<N, B>(&good[1]).expect("line 2 parses");
    assert!(matches!(direct.process(&f1, None), Ok(Step::First)));
    let Ok(Step::Structure(s)) = direct.process(&f2, m2.as_ref()) else {
        panic!("the example pair gives a structure")
    };
    assert_eq!(out.result, "structure", "{:?}", out.error);
    assert_eq!(out.boundaries.len(), s.boundaries().len());
    for (ob, sb) in out.boundaries.iter().zip(s.boundaries()) {
        assert_eq!(ob.len(), sb.points().len());
        for (op, sp) in ob.iter().zip(sb.points()) {
            assert_eq!(op.status, sp.status().name());
            assert_eq!(op.xyz, s.point(sp));
            assert_eq!(op.z_far, sp.interval().map(|i| i.z_far));
        }
    }
}

/// Lines joined with `\n`, as bytes.
fn join(lines: &[&[u8]]) -> Vec<u8> {
    lines.join(&b"\n"[..])
}

/// Issue 15, item 4: a line that is not UTF-8 used to abort the whole run
/// (`read error: stream did not contain valid UTF-8`, no line number).
/// Now it is an error line naming the line and the byte, and the next
/// line is processed as usual (against the kept frame of line 1).
#[test]
fn invalid_utf8_is_an_error_naming_the_line_and_the_run_goes_on() {
    let good = example();
    let mut bad = good[1].as_bytes().to_vec();
    bad[20] = 0xff;
    let (out, errors, done) = run(&join(&[
        good[0].as_bytes(),
        b"{\"camera\": \xfe\xff}",
        &bad,
        good[1].as_bytes(),
    ]));
    assert_eq!(
        done,
        Replayed {
            lines: 4,
            errors: 2
        }
    );
    assert_eq!(out.len(), 4);
    assert_eq!(out[0].result, "first");
    for (o, byte) in [(&out[1], 11), (&out[2], 20)] {
        assert_eq!(o.result, "error");
        let e = o.error.clone().unwrap_or_default();
        assert_eq!(
            e,
            format!("line {}: invalid UTF-8 at byte {byte} of the line", o.line)
        );
    }
    assert_eq!(errors.len(), 2);
    assert_is_the_example_pair(&out[3]);
}

/// Text after the frame object, and a second object on the same line, are
/// errors naming the line (they used to be ignored: the first object was
/// processed). Trailing whitespace and a CRLF line ending are fine.
#[test]
fn text_after_the_object_is_an_error_naming_the_line() {
    let good = example();
    let garbage = format!("{} garbage", good[1]);
    let two = format!("{}{}", good[1], good[1]);
    let two_spaced = format!("{} {}", good[1], good[0]);
    let spaced = format!("{}  \t\r", good[1]);
    let (out, errors, done) = run(&join(&[
        good[0].as_bytes(),
        garbage.as_bytes(),
        two.as_bytes(),
        two_spaced.as_bytes(),
        spaced.as_bytes(),
    ]));
    assert_eq!(
        done,
        Replayed {
            lines: 5,
            errors: 3
        }
    );
    let col = good[1].len() + 1;
    assert_eq!(
        out[1].error.as_deref(),
        Some(
            format!(
                "line 2: text after the frame object at column {} (one frame object per line)",
                col + 1
            )
            .as_str()
        )
    );
    assert_eq!(
        out[2].error.as_deref(),
        Some(format!("line 3: a second JSON object after the frame object at column {col} (one frame object per line)").as_str())
    );
    let e = out[3].error.clone().unwrap_or_default();
    assert!(e.starts_with("line 4: a second JSON object"), "{e}");
    assert_eq!(errors, [1, 2, 3].map(|i| out[i].error.clone().unwrap()));
    // Line 5 pairs with the frame kept from line 1: the rejected lines
    // did not replace it.
    assert_is_the_example_pair(&out[4]);
}

/// The documented format has `camera` and `motion` as objects and a line
/// as an object; the arrays of their values that serde's derive would
/// also take are errors naming the line and the field.
#[test]
fn camera_motion_and_line_must_be_objects() {
    let good = example();
    let v: serde_json::Value = serde_json::from_str(&good[1]).unwrap();
    let with = |field: &str, value: serde_json::Value| {
        let mut v = v.clone();
        v[field] = value;
        v.to_string()
    };
    let c = &v["camera"];
    let camera_seq = with(
        "camera",
        serde_json::json!([c["fx"], c["fy"], c["cx"], c["cy"], c["width"], c["height"]]),
    );
    let m = &v["motion"];
    let motion_seq = with(
        "motion",
        serde_json::json!([m["translation"], m["rotation"]]),
    );
    let line_seq = serde_json::json!([v["camera"], v["motion"], v["boundaries"]]).to_string();
    // serde's derive takes these (the check that they are well formed).
    let derived: Result<host_tests::jsonl::FrameIn, _> = serde_json::from_str(&line_seq);
    assert!(derived.is_ok());
    let (out, _, done) = run(&join(&[
        good[0].as_bytes(),
        camera_seq.as_bytes(),
        motion_seq.as_bytes(),
        line_seq.as_bytes(),
        good[1].as_bytes(),
    ]));
    assert_eq!(
        done,
        Replayed {
            lines: 5,
            errors: 3
        }
    );
    let err = |i: usize| out[i].error.clone().unwrap_or_default();
    assert!(
        err(1)
            .starts_with("line 2: field `camera`: invalid type: sequence, expected a JSON object"),
        "{}",
        err(1)
    );
    assert!(
        err(2)
            .starts_with("line 3: field `motion`: invalid type: sequence, expected a JSON object"),
        "{}",
        err(2)
    );
    assert!(
        err(3).starts_with("line 4: invalid JSON: invalid type: sequence, expected a JSON object"),
        "{}",
        err(3)
    );
    assert_is_the_example_pair(&out[4]);
}

/// The tool itself, end to end: every kind of bad line on standard input
/// gives its error line and a message on standard error, the good lines
/// are processed, blank lines are skipped, and the exit code is 1 (some
/// lines rejected), not 2 (an aborted run).
#[test]
fn the_replay_tool_reports_each_bad_line_and_goes_on() {
    use std::io::Write;
    use std::process::{Command, Stdio};
    let good = example();
    let input = join(&[
        good[0].as_bytes(),
        b"\xff",
        b"",
        format!("{} trailing", good[1]).as_bytes(),
        good[1].as_bytes(),
    ]);
    let mut child = Command::new(env!("CARGO_BIN_EXE_replay"))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("replay starts");
    child.stdin.take().unwrap().write_all(&input).unwrap();
    let done = child.wait_with_output().expect("replay runs");
    assert_eq!(done.status.code(), Some(1));
    let stdout = String::from_utf8(done.stdout).unwrap();
    let outs: Vec<LineOut> = stdout
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let summary: Vec<(usize, &str)> = outs.iter().map(|o| (o.line, o.result.as_str())).collect();
    assert_eq!(
        summary,
        [(1, "first"), (2, "error"), (4, "error"), (5, "structure")]
    );
    assert_is_the_example_pair(&outs[3]);
    let stderr = String::from_utf8(done.stderr).unwrap();
    assert!(
        stderr.contains("replay: line 2: invalid UTF-8 at byte 0"),
        "{stderr}"
    );
    assert!(
        stderr.contains("replay: line 4: text after the frame object"),
        "{stderr}"
    );
    assert!(stderr.contains("2 line(s) rejected"), "{stderr}");
}

/// The worked example of README ("Replay") is current: `docs/example_out.jsonl`
/// is what the replay gives for `docs/example.jsonl` today, and the point
/// README quotes from it is in it. (A check that the docs did not go
/// stale, not of the results' accuracy, which the generator's truth
/// checks elsewhere: regenerate both with `cargo xtask figures`. An
/// integrator's review found the file 202 fields behind the code.)
#[test]
fn the_worked_example_in_the_docs_is_current() {
    let expected = include_str!("../../docs/example_out.jsonl");
    let mut p = Box::new(Processor::<N, B>::new(Config::default()));
    let mut got = String::new();
    for (i, line) in example().iter().enumerate() {
        let out = process_line(&mut p, i + 1, line);
        got.push_str(&serde_json::to_string(&out).expect("serialises"));
        got.push('\n');
    }
    assert!(
        got == expected,
        "docs/example_out.jsonl is stale: run `cargo xtask figures`"
    );
    let readme = include_str!("../../README.md");
    let start = readme
        .find("{\"p1\":[108.0,240.0]")
        .expect("README quotes a point of the example");
    let quoted = readme[start..].lines().next().expect("a line");
    assert!(
        expected.contains(quoted),
        "README's quoted point is not in docs/example_out.jsonl: {quoted}"
    );
}
