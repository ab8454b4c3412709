//! The adversarial benchmark family (host_tests/src/drive/adversarial.rs):
//! write its frame pairs for the bench firmware, time them on the host, or
//! search for costlier ones.
//!
//! ```text
//! cargo run --release --bin adversarial                    # write src/bin/data/adv_*.bin + adversarial.rs
//! cargo run --release --bin adversarial -- --list          # host cost of every member at every N
//! cargo run --release --bin adversarial -- --search --seed 1 [--iters 2000] [--keep 3] [--reps 5]
//! ```
//!
//! The search starts from the hand-made members, mutates them at random
//! (seeded SplitMix64: [`adversarial::mutate`]; every mutation is in paper
//! pixels or counted from a boundary's end, so a mutant is the same scene
//! at every N), keeps only mutants that pass validation at every N, and
//! scores each by the host cost at N = 256: the best of `--reps` timings
//! of the release build's `Processor::process` for frame 2. Parents are
//! chosen by a tournament of three (or six, half the time) over the members
//! and the mutants so far.
//! At the end the costliest mutants are timed again (3 × `--reps`), and the
//! `--keep` costliest of distinct shapes (scene, rounding, direction, frames with
//! spurious points, FOE moved, zig-zag, lift) are written to
//! `src/drive/adversarial_found.json` as `search_1`, `search_2`, …, then
//! every data file is rewritten (`--no-write` skips both).
//!
//! Host timing is noisy and machine-dependent, so two runs with the same
//! seed can keep different mutants when their costs are close; what is
//! kept is stored as parameters, so rendering it is deterministic, and the
//! bench's figures are the firmware's. The costliest inputs depend on the
//! implementation: rerun the search after the matching stage changes.

use std::collections::HashSet;
use std::path::PathBuf;

use host_tests::drive::adversarial::{
    self, family, hand_members, host_cost, mutate, render, valid_everywhere, Errors, Foe, Member,
    Params, Scene, SIZES,
};
use host_tests::synth::Rng;

struct Args {
    list: bool,
    search: bool,
    seed: u64,
    iters: usize,
    keep: usize,
    reps: usize,
    write: bool,
    out: PathBuf,
}

const USAGE: &str = "usage: adversarial [--list] [--search --seed S [--iters 2000] [--keep 3]] [--reps 5] [--no-write] [--out ../src/bin/data]";

fn args() -> Result<Args, String> {
    let mut a = Args {
        list: false,
        search: false,
        seed: 1,
        iters: 2000,
        keep: 3,
        reps: 5,
        write: true,
        out: PathBuf::from("../src/bin/data"),
    };
    let mut it = std::env::args().skip(1);
    while let Some(x) = it.next() {
        let mut num = || -> Result<u64, String> {
            it.next()
                .and_then(|v| v.parse().ok())
                .ok_or(format!("{x} needs a number\n{USAGE}"))
        };
        match x.as_str() {
            "--list" => a.list = true,
            "--search" => a.search = true,
            "--seed" => a.seed = num()?,
            "--iters" => a.iters = num()? as usize,
            "--keep" => a.keep = num()? as usize,
            "--reps" => a.reps = num()? as usize,
            "--no-write" => a.write = false,
            "--out" => a.out = PathBuf::from(it.next().ok_or(USAGE)?),
            _ => return Err(USAGE.into()),
        }
    }
    // A host table alone writes nothing.
    if a.list && !a.search {
        a.write = false;
    }
    Ok(a)
}

/// Host cost of `p` at `n` (ns), or `None` when it does not render.
fn cost(p: &Params, n: usize, reps: usize) -> Option<(f64, Vec<(String, usize)>)> {
    cost_with(p, n, reps, Errors::Default)
}

/// [`cost`] under an error model.
fn cost_with(
    p: &Params,
    n: usize,
    reps: usize,
    errors: Errors,
) -> Option<(f64, Vec<(String, usize)>)> {
    let (k, f) = render(p, n).ok()?;
    Some(host_cost(&k, &f, reps, errors))
}

fn statuses(s: &[(String, usize)]) -> String {
    s.iter()
        .map(|(n, c)| format!("{n} {c}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The host cost table of `members` at every N.
fn list(members: &[Member], reps: usize) {
    let base: Vec<f64> = SIZES
        .iter()
        .map(|&n| cost(&Params::fig6(), n, reps).map_or(f64::NAN, |c| c.0))
        .collect();
    println!("| member | N | host us | x representative | statuses |");
    println!("|---|---:|---:|---:|---|");
    for m in members {
        for (i, &n) in SIZES.iter().enumerate() {
            match cost_with(&m.params, n, reps, m.errors) {
                Some((ns, st)) => println!(
                    "| {} | {n} | {:.1} | {:.1} | {} |",
                    m.name,
                    ns / 1e3,
                    ns / base[i],
                    statuses(&st)
                ),
                None => println!("| {} | {n} | invalid | | |", m.name),
            }
        }
    }
}

/// What makes two mutants the same kind of input, for keeping distinct
/// ones: the scene, the rounding, the frames with spurious points, whether
/// the FOE was moved, which frames zig-zag, whether a vertex is lifted.
fn shape(p: &Params) -> String {
    let scene = match p.scene {
        Scene::Fig6 => "fig6",
        Scene::Straight => "straight",
        Scene::Spiral { .. } => "spiral",
    };
    let spur_frames = p.spurious.iter().fold(0, |m, s| m | s.frames);
    format!(
        "{scene} q{} back:{} spurs:{spur_frames} foe:{} zz:{}{} lift:{}",
        p.quantise,
        p.reverse,
        matches!(p.foe, Foe::At { .. }),
        p.zigzag[0] > 0.0,
        p.zigzag[1] > 0.0,
        p.lift.is_some(),
    )
}

/// A one-line description of a mutant's parameters.
fn describe(p: &Params) -> String {
    let scene = match p.scene {
        Scene::Fig6 => "the Fig. 6 road and motion".to_string(),
        Scene::Straight => "a straight road driven straight".to_string(),
        Scene::Spiral { deg } => format!("log spirals {deg:.2} degrees from the FOE direction"),
    };
    let mut s = format!(
        "{scene}, columns {}, {:?} rows",
        if p.quantise { "rounded" } else { "exact" },
        p.rows
    );
    if p.reverse {
        s += ", driven backwards";
    }
    if let Foe::At { u, v } = p.foe {
        s += &format!(", FOE at ({u:.1}, {v:.1})");
    }
    if p.turn != [0.0; 3] {
        s += &format!(
            ", camera 2 turned ({:.2}, {:.2}, {:.2}) degrees",
            p.turn[0], p.turn[1], p.turn[2]
        );
    }
    if p.zigzag != [0.0; 2] {
        s += &format!(
            ", zig-zag {:.1} / {:.1} px (frame 1 / 2)",
            p.zigzag[0], p.zigzag[1]
        );
    }
    for sp in &p.spurious {
        s += &format!(
            ", spurious vertex {}{} of boundary {} in frame {} at {:.2} of the width",
            if sp.from_end { "N-1-" } else { "" },
            sp.k,
            sp.boundary,
            match sp.frames {
                1 => "1",
                2 => "2",
                _ => "1 and 2",
            },
            sp.u
        );
    }
    if let Some(l) = p.lift {
        s += &format!(
            ", top frame-1 vertex of boundary {} {:.1} px above the FOE row",
            l.boundary, l.above
        );
    }
    if p.top > 0.0 {
        s += &format!(", rows from {:.0} down", p.top);
    }
    s
}

fn search(a: &Args) -> Vec<Member> {
    let mut g = Rng(a.seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0xAD5E);
    let repr = cost(&Params::fig6(), 256, a.reps).map_or(f64::NAN, |c| c.0);
    println!(
        "search: seed {}, {} iterations, N = 256, the representative pair {:.1} us on this host",
        a.seed,
        a.iters,
        repr / 1e3
    );
    let mut pool: Vec<(f64, Params)> = Vec::new();
    // The search mutates the pair, not the error model: it starts from the
    // members with the default one.
    for m in hand_members()
        .into_iter()
        .filter(|m| m.errors == Errors::Default)
    {
        if let Some((ns, _)) = cost(&m.params, 256, a.reps) {
            println!("  start {:18} {:8.1} us", m.name, ns / 1e3);
            pool.push((ns, m.params));
        }
    }
    let starts = pool.len();
    let mut seen: HashSet<String> = pool
        .iter()
        .map(|(_, p)| serde_json::to_string(p).unwrap_or_default())
        .collect();
    let mut best = pool.iter().map(|c| c.0).fold(0.0, f64::max);
    for it in 1..=a.iters {
        // Tournament of three (of six half the time) over everything
        // evaluated so far.
        let size = if g.chance(0.5) { 6 } else { 3 };
        let parent = (0..size)
            .map(|_| &pool[(g.next_u64() % pool.len() as u64) as usize])
            .max_by(|x, y| x.0.total_cmp(&y.0))
            .map(|c| c.1.clone())
            .unwrap_or_else(Params::fig6);
        let mut child = mutate(&parent, &mut g);
        while g.chance(0.4) {
            child = mutate(&child, &mut g);
        }
        let key = serde_json::to_string(&child).unwrap_or_default();
        if !seen.insert(key) || !valid_everywhere(&child) {
            continue;
        }
        let Some((ns, _)) = cost(&child, 256, a.reps) else {
            continue;
        };
        if ns > best {
            best = ns;
            println!(
                "  iteration {it:4}: {:8.1} us ({:.1} x the representative): {}",
                ns / 1e3,
                ns / repr,
                describe(&child)
            );
        }
        pool.push((ns, child));
    }
    // Time the costliest mutants again, keep the costliest distinct shapes.
    let mut mutants: Vec<(f64, Params)> = pool.split_off(starts);
    mutants.sort_by(|x, y| y.0.total_cmp(&x.0));
    mutants.truncate(12 * a.keep.max(1));
    for m in mutants.iter_mut() {
        m.0 = cost(&m.1, 256, 3 * a.reps).map_or(0.0, |c| c.0);
    }
    mutants.sort_by(|x, y| y.0.total_cmp(&x.0));
    let mut shapes = HashSet::new();
    let mut kept = Vec::new();
    for (ns, p) in mutants {
        if kept.len() == a.keep {
            break;
        }
        if !shapes.insert(shape(&p)) {
            continue;
        }
        kept.push(Member {
            name: format!("search_{}", kept.len() + 1),
            what: format!(
                "seeded search (seed {}, {} iterations), host cost at N = 256 {:.1} x the representative: {}",
                a.seed,
                a.iters,
                ns / repr,
                describe(&p)
            ),
            params: p,
            errors: adversarial::Errors::Default,
        });
    }
    kept
}

fn main() -> std::process::ExitCode {
    let a = match args() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("{e}");
            return std::process::ExitCode::from(2);
        }
    };
    let mut members = family();
    if a.search {
        let kept = search(&a);
        println!("\nkept:");
        for m in &kept {
            println!("  {}: {}", m.name, m.what);
        }
        // Render what the file will hold, parsed back, so the data files are
        // exactly what the tests regenerate from it.
        let json = serde_json::to_string_pretty(&kept).unwrap_or_default() + "\n";
        let kept: Vec<Member> = serde_json::from_str(&json).unwrap_or_default();
        members = hand_members();
        members.extend(kept);
        if a.write {
            let path =
                PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src/drive/adversarial_found.json");
            if let Err(e) = std::fs::write(&path, json) {
                eprintln!("{}: {e}", path.display());
                return std::process::ExitCode::FAILURE;
            }
            println!("wrote {}", path.display());
        }
    }
    if a.list {
        list(&members, a.reps);
    }
    if a.write {
        match adversarial::write_all(&a.out, &members) {
            Ok(bytes) => println!(
                "wrote {} members x N = {:?} ({} files, {bytes} bytes) and adversarial.rs to {}",
                members.len(),
                SIZES,
                members.len() * SIZES.len(),
                a.out.display()
            ),
            Err(e) => {
                eprintln!("{e}");
                return std::process::ExitCode::FAILURE;
            }
        }
    }
    std::process::ExitCode::SUCCESS
}
