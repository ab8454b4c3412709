//! The JSON Lines replay: good lines give the library's results, bad lines
//! give an error naming the line and the field, and processing goes on.

use host_tests::jsonl::{parse_line, process_line, LineOut};
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
