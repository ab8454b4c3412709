//! Stream a recorded drive into the link firmware on QEMU over UART0 and
//! compare every output packet with the host build, bit for bit.
//!
//! `stream --elf ELF [--drive] FILE [--corrupt P] [--drop P] [--duplicate P]
//! [--seed S] [--radius PX] [--frames K] [--within]`
//!
//! With `--within` the firmware runs each frame within a deadline (its
//! feature `link-deadline`): then each result must be the host's point for
//! point, or `over_budget` where the deadline cut the frame, and every
//! frame within the frame budget; every other packet bit for bit.
//!
//! With `--fused` the firmware runs each frame through a key-frame fusion
//! (its feature `link-fused`), the host too: every packet bit for bit and
//! the fusion's digest after every frame (from the firmware's log) the
//! host's. With both, a pair the clock cut does not count towards the
//! key-frame policy, so the key frames may differ from the host's after
//! one: a result of another pair than the host's is counted, not a
//! divergence, and the digests are not compared; the rest as `--within`.
//!
//! FILE is replay JSON Lines, or with `--drive` the firmware drive format
//! (`src/bin/data/drive.bin`). `cargo xtask stream` builds the firmware and
//! calls this. Exit code 1 on any divergence.

use std::collections::BTreeMap;
use std::io::{Read, Write};
use std::os::unix::net::UnixStream;
use std::process::{Command, ExitCode, Stdio};
use std::time::{Duration, Instant};

use host_tests::link::{self, Faults, Kind};
use roadstereo::wire::result::{check, report};
use roadstereo::wire::{ErrorKind, PacketType, ResultView};
use roadstereo::Status;

const BUDGET_INSTRUCTIONS: u64 = 33 * 168_000 / 20;

struct Args {
    elf: String,
    file: String,
    drive: bool,
    faults: Faults,
    radius: f32,
    frames: Option<usize>,
    within: bool,
    fused: bool,
}

fn args() -> Result<Args, String> {
    let mut a = Args {
        elf: String::new(),
        file: String::new(),
        drive: false,
        faults: Faults::default(),
        radius: 0.5,
        frames: None,
        within: false,
        fused: false,
    };
    let mut it = std::env::args().skip(1);
    while let Some(x) = it.next() {
        let mut val = |name: &str| it.next().ok_or(format!("{name} needs a value"));
        match x.as_str() {
            "--elf" => a.elf = val("--elf")?,
            "--drive" => a.drive = true,
            "--within" => a.within = true,
            "--fused" => a.fused = true,
            "--corrupt" => {
                a.faults.corrupt = val("--corrupt")?
                    .parse()
                    .map_err(|e| format!("--corrupt: {e}"))?
            }
            "--drop" => {
                a.faults.drop = val("--drop")?.parse().map_err(|e| format!("--drop: {e}"))?
            }
            "--duplicate" => {
                a.faults.duplicate = val("--duplicate")?
                    .parse()
                    .map_err(|e| format!("--duplicate: {e}"))?
            }
            "--seed" => {
                a.faults.seed = val("--seed")?.parse().map_err(|e| format!("--seed: {e}"))?
            }
            "--radius" => {
                a.radius = val("--radius")?
                    .parse()
                    .map_err(|e| format!("--radius: {e}"))?
            }
            "--frames" => {
                a.frames = Some(
                    val("--frames")?
                        .parse()
                        .map_err(|e| format!("--frames: {e}"))?,
                )
            }
            f if !f.starts_with("--") && a.file.is_empty() => a.file = f.to_string(),
            other => return Err(format!("unknown argument {other}")),
        }
    }
    for p in [a.faults.corrupt, a.faults.drop, a.faults.duplicate] {
        if !(0.0..=1.0).contains(&p) {
            return Err("fault probabilities must be in [0, 1]".into());
        }
    }
    if a.elf.is_empty() || a.file.is_empty() {
        return Err("usage: stream --elf ELF [--drive] FILE [--corrupt P] [--drop P] [--duplicate P] [--seed S] [--radius PX] [--frames K] [--within] [--fused]".into());
    }
    Ok(a)
}

/// Run the firmware with UART0 on a Unix socket; write `input`, read the
/// output link bytes until the summary packet (or the firmware exits).
fn run_qemu(elf: &str, input: &[u8]) -> Result<(Vec<u8>, String, f64), String> {
    let elf = std::fs::canonicalize(elf).map_err(|e| format!("{elf}: {e}"))?;
    let dir = std::env::temp_dir().join(format!("roadstereo-stream-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let sock = dir.join("uart0.sock");
    let _ = std::fs::remove_file(&sock);
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let chardev = format!("socket,id=link,path={},server=on,wait=on", sock.display());
    let mut child = Command::new("bash")
        .arg(root.join(".cargo/qemu-run.sh"))
        .arg(&elf)
        .args(["-chardev", &chardev, "-serial", "chardev:link"])
        .current_dir(&root)
        .stdout(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot start QEMU: {e}"))?;
    let start = Instant::now();
    let mut conn = loop {
        match UnixStream::connect(&sock) {
            Ok(c) => break c,
            Err(_) if start.elapsed() < Duration::from_secs(30) => {
                std::thread::sleep(Duration::from_millis(50))
            }
            Err(e) => {
                let _ = child.kill();
                return Err(format!("cannot connect to QEMU's UART0 socket: {e}"));
            }
        }
    };
    let t0 = Instant::now();
    let mut writer = conn.try_clone().map_err(|e| e.to_string())?;
    let data = input.to_vec();
    let w = std::thread::spawn(move || {
        for c in data.chunks(256) {
            if writer.write_all(c).is_err() {
                return;
            }
        }
        let _ = writer.flush();
    });
    conn.set_read_timeout(Some(Duration::from_secs(300)))
        .map_err(|e| e.to_string())?;
    let mut out = Vec::new();
    let mut buf = [0u8; 4096];
    loop {
        match conn.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => {
                out.extend_from_slice(&buf[..n]);
                // The summary packet is the last thing the firmware sends.
                if n > 0 && buf[n - 1] == 0 {
                    let frames = link::split_link(&out);
                    if let Some(Ok(last)) = frames.last() {
                        if link::type_of(last) == Some(PacketType::Summary) {
                            break;
                        }
                    }
                }
            }
            Err(e) => {
                let _ = child.kill();
                return Err(format!("reading UART0: {e}"));
            }
        }
    }
    let secs = t0.elapsed().as_secs_f64();
    let _ = w.join();
    drop(conn);
    let mut log = String::new();
    if let Some(mut s) = child.stdout.take() {
        let _ = s.read_to_string(&mut log);
    }
    let status = child.wait().map_err(|e| e.to_string())?;
    let _ = std::fs::remove_dir_all(&dir);
    if !status.success() {
        return Err(format!("firmware failed ({status})\n{log}"));
    }
    Ok((out, log, secs))
}

fn main() -> ExitCode {
    let a = match args() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("stream: {e}");
            return ExitCode::from(2);
        }
    };
    let frames = match std::fs::read(&a.file)
        .map_err(|e| e.to_string())
        .and_then(|b| {
            if a.drive {
                link::from_drive(&b)
            } else {
                link::from_jsonl(&String::from_utf8_lossy(&b))
            }
        }) {
        Ok(mut f) => {
            if let Some(k) = a.frames {
                f.truncate(k);
            }
            f
        }
        Err(e) => {
            eprintln!("stream: {}: {e}", a.file);
            return ExitCode::from(2);
        }
    };
    let packets = match link::packets(&frames, a.radius) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("stream: {e}");
            return ExitCode::from(2);
        }
    };
    let (stream, injected) = link::inject(&packets, &a.faults);
    let frame_packets = packets.iter().filter(|p| p.kind == Kind::Frame).count();
    println!(
        "stream: {} frames, {} packets, {} bytes in; faults injected: {} corrupted, {} dropped, {} duplicated (seed {})",
        frames.len(),
        packets.len(),
        stream.len(),
        injected.corrupted,
        injected.dropped,
        injected.duplicated,
        a.faults.seed
    );
    // The host reference on the same bytes, and the clean run (no faults)
    // for the pairs the faulty run shares with it.
    let outputs = |s: &[u8]| {
        if a.fused {
            link::host_outputs_fused(s, 61)
        } else {
            (link::host_outputs(s, 61), Vec::new())
        }
    };
    let (host, host_digests) = outputs(&stream);
    let (clean_stream, _) = link::inject(&packets, &Faults::default());
    let (clean, _) = outputs(&clean_stream);
    let (fw_bytes, log, secs) = match run_qemu(&a.elf, &stream) {
        Ok(x) => x,
        Err(e) => {
            eprintln!("stream: {e}");
            return ExitCode::FAILURE;
        }
    };
    println!(
        "stream: {} bytes in, {} bytes out in {secs:.1} s",
        stream.len(),
        fw_bytes.len()
    );
    let fw: Vec<Vec<u8>> = link::split_link(&fw_bytes)
        .into_iter()
        .map(|r| r.unwrap_or_default())
        .collect();

    let mut divergences = Vec::new();
    // With the fusion: its digest after every frame, as the firmware
    // logged it, against the host's (not within a deadline, see above).
    if a.fused && !a.within {
        let fw_digests = fused_digests(&log);
        if fw_digests != host_digests {
            let at = fw_digests
                .iter()
                .zip(&host_digests)
                .position(|(f, h)| f != h)
                .unwrap_or(fw_digests.len().min(host_digests.len()));
            divergences.push(format!(
                "the fusion's digests differ from the host's from frame run {at} ({} logged, {} on the host)",
                fw_digests.len(),
                host_digests.len()
            ));
        }
    }
    // Within a deadline with the fusion: results of another pair than the
    // host's (the key frames differ after a cut).
    let mut other_pairs = 0usize;
    if fw.len() != host.len() {
        divergences.push(format!(
            "firmware sent {} packets, host {}",
            fw.len(),
            host.len()
        ));
    }
    // Every packet, bit for bit (a result's instruction count is the
    // firmware's own and is set to 0 for the comparison).
    let mut compared = 0usize;
    // Within a deadline: the frames the clock cut, their points flagged
    // for it, and the frames over the budget.
    let (mut cut_frames, mut cut_points, mut looser_sticks) = (0usize, 0u64, 0u64);
    let mut fw_errors: BTreeMap<ErrorKind, u32> = BTreeMap::new();
    let mut host_errors: BTreeMap<ErrorKind, u32> = BTreeMap::new();
    let mut rows = Vec::new();
    for (i, (f, h)) in fw.iter().zip(&host).enumerate() {
        let mut f0 = f.clone();
        if link::type_of(f) == Some(PacketType::Result) {
            ResultView::zero_instructions(&mut f0);
        }
        let both_results = link::type_of(f) == Some(PacketType::Result)
            && link::type_of(h) == Some(PacketType::Result);
        if a.within && a.fused && both_results && pair_of(f) != pair_of(h) {
            other_pairs += 1;
        } else if a.within && both_results {
            match within_matches(f, h) {
                Ok((flagged, looser, cut)) => {
                    cut_frames += usize::from(cut);
                    cut_points += flagged;
                    looser_sticks += looser;
                }
                Err(e) => divergences.push(format!("output packet {i}: {e}")),
            }
        } else if &f0 != h {
            divergences.push(format!("output packet {i} differs"));
        }
        if let Ok(c) = check(f) {
            match c.ptype {
                PacketType::Result => {
                    if let Ok(v) = ResultView::parse(c.payload) {
                        if v.structure {
                            compared += 1;
                        }
                        rows.push(v.clone_owned());
                    }
                }
                PacketType::Report => {
                    if let Some(r) = report(c.payload) {
                        *fw_errors.entry(r.kind).or_default() += 1;
                    }
                }
                _ => {}
            }
        } else {
            divergences.push(format!("output packet {i} does not check"));
        }
    }
    for h in &host {
        if let Ok(c) = check(h) {
            if c.ptype == PacketType::Report {
                if let Some(r) = report(c.payload) {
                    *host_errors.entry(r.kind).or_default() += 1;
                }
            }
        }
    }
    // The pairs both runs have: the same results (payloads without the
    // counter, so a fault before them changed nothing).
    let key = |raw: &Vec<u8>| -> Option<((u32, u32), Vec<u8>)> {
        let c = check(raw).ok()?;
        (c.ptype == PacketType::Result).then_some(())?;
        let v = ResultView::parse(c.payload).ok()?;
        v.structure
            .then(|| ((v.kept_id, v.frame_id), c.payload.to_vec()))
    };
    let clean_pairs: BTreeMap<(u32, u32), Vec<u8>> = clean.iter().filter_map(key).collect();
    let (mut shared, mut shared_same) = (0usize, 0usize);
    for (k, payload) in host.iter().filter_map(key) {
        if let Some(c) = clean_pairs.get(&k) {
            shared += 1;
            if *c == payload {
                shared_same += 1;
            } else {
                divergences.push(format!("pair {k:?} differs from the fault-free run"));
            }
        }
    }

    println!();
    println!(
        "| frame | kept | points | ok | flagged | instructions | instr/point | frame budget used | the deadline cut it |"
    );
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|---|");
    for r in rows.iter().filter(|r| r.structure) {
        let points = r.total;
        let ok = u64::from(r.ok);
        println!(
            "| {} | {} | {} | {} | {} | {} | {} | {:.1} % | {} |",
            r.frame_id,
            r.kept_id,
            points,
            ok,
            points - ok,
            r.instructions,
            u64::from(r.instructions) / points.max(1),
            f64::from(r.instructions) * 100.0 / BUDGET_INSTRUCTIONS as f64,
            if r.deadline_expired { "yes" } else { "" }
        );
    }
    println!();
    println!("| error reported | firmware | host |");
    println!("|---|---:|---:|");
    let kinds: std::collections::BTreeSet<_> = fw_errors
        .keys()
        .chain(host_errors.keys())
        .copied()
        .collect();
    for k in &kinds {
        println!(
            "| {} | {} | {} |",
            k.name(),
            fw_errors.get(k).copied().unwrap_or(0),
            host_errors.get(k).copied().unwrap_or(0)
        );
    }
    if kinds.is_empty() {
        println!("| (none) | 0 | 0 |");
    }
    println!();
    println!(
        "| faults injected (corrupted / dropped / duplicated) | errors reported | frame packets sent | frames compared {} | pairs also in the fault-free run, identical | divergences |",
        if a.within {
            "(within a deadline: the host's or `over_budget`)"
        } else {
            "bit for bit"
        }
    );
    println!("|---|---:|---:|---:|---:|---:|");
    println!(
        "| {} / {} / {} | {} | {} | {} | {} / {} | {} |",
        injected.corrupted,
        injected.dropped,
        injected.duplicated,
        fw_errors.values().sum::<u32>(),
        frame_packets,
        compared,
        shared_same,
        shared,
        divergences.len()
    );
    if a.within {
        let worst = rows
            .iter()
            .filter(|r| r.structure)
            .map(|r| r.instructions)
            .max()
            .unwrap_or(0);
        let host_ok: u64 = host
            .iter()
            .filter_map(|h| check(h).ok())
            .filter(|c| c.ptype == PacketType::Result)
            .filter_map(|c| ResultView::parse(c.payload).ok())
            .map(|v| u64::from(v.count(Status::Ok)))
            .sum();
        let fw_ok: u64 = rows.iter().map(|r| u64::from(r.ok)).sum();
        println!();
        println!(
            "stream: within a deadline: the clock cut {cut_frames} of {compared} frames; {cut_points} points `over_budget` that were not without a deadline, {looser_sticks} sticks left looser; `ok` points {fw_ok} against {host_ok} without a deadline; the costliest frame {worst} instructions, {:.1} % of the budget {BUDGET_INSTRUCTIONS}{}",
            f64::from(worst) * 100.0 / BUDGET_INSTRUCTIONS as f64,
            if a.fused {
                format!("; {other_pairs} results of another pair than the host's (key frames differ after a cut)")
            } else {
                String::new()
            }
        );
        if u64::from(worst) > BUDGET_INSTRUCTIONS {
            divergences.push(format!(
                "a frame took {worst} instructions within a deadline, over the budget {BUDGET_INSTRUCTIONS}"
            ));
        }
    }
    if divergences.is_empty() {
        println!(
            "stream: firmware and host agree on all {} output packets ({} frames with a structure; {})",
            fw.len(),
            compared,
            if a.within {
                "each result the host's or `over_budget` point for point, the rest bit for bit".to_string()
            } else if a.fused {
                format!("bit for bit, and the fusion's digest after each of {} frames run", host_digests.len())
            } else {
                "bit for bit".to_string()
            }
        );
        ExitCode::SUCCESS
    } else {
        for d in divergences.iter().take(20) {
            eprintln!("stream: divergence: {d}");
        }
        ExitCode::FAILURE
    }
}

/// The `(kept, frame)` ids and whether there is a structure, of a result
/// packet.
fn pair_of(raw: &[u8]) -> Option<(u32, u32, bool)> {
    let c = check(raw).ok()?;
    let v = ResultView::parse(c.payload).ok()?;
    Some((v.kept_id, v.frame_id, v.structure))
}

/// The fusion's digest after each frame run, from the link firmware's
/// log lines `fused frame=F ... fusion_digest=D` (feature `link-fused`).
fn fused_digests(log: &str) -> Vec<(u32, u32)> {
    let field = |line: &str, name: &str| -> Option<String> {
        let at = line.find(name)? + name.len();
        Some(line[at..].split_whitespace().next()?.to_string())
    };
    log.lines()
        .filter(|l| l.contains("fused frame="))
        .filter_map(|l| {
            let frame = field(l, "fused frame=")?.parse().ok()?;
            let digest = u32::from_str_radix(&field(l, "fusion_digest=")?, 16).ok()?;
            Some((frame, digest))
        })
        .collect()
}

/// A result's fields for the table (the view borrows the packet).
struct Row {
    frame_id: u32,
    kept_id: u32,
    structure: bool,
    instructions: u32,
    /// Points counted, and `ok` ones.
    total: u64,
    ok: u16,
    deadline_expired: bool,
}

trait Owned {
    fn clone_owned(&self) -> Row;
}
impl Owned for ResultView<'_> {
    fn clone_owned(&self) -> Row {
        Row {
            frame_id: self.frame_id,
            kept_id: self.kept_id,
            structure: self.structure,
            instructions: self.instructions,
            total: self.total(),
            ok: self.count(Status::Ok),
            deadline_expired: self.deadline_expired,
        }
    }
}

/// Within a deadline: the firmware's result packet `f` against the host's
/// `h` (no deadline): the same pair, boundaries and point count, and each
/// point the host's, or `over_budget` with no depth (the clock said yes
/// first, or the deadline's cap on one point's search,
/// `roadstereo::deadline::CARRY`, bound it), or the host's depth with a
/// stick that holds the host's (the cap left a stick unrefined, looser and
/// still guaranteed): nothing else (`roadstereo::deadline`). The count of
/// points flagged and of sticks left looser, and whether the clock cut the
/// frame.
fn within_matches(f: &[u8], h: &[u8]) -> Result<(u64, u64, bool), String> {
    let view = |raw| {
        check(raw)
            .ok()
            .and_then(|c| ResultView::parse(c.payload).ok())
            .ok_or("a result that does not parse")
    };
    let (vf, vh) = (view(f)?, view(h)?);
    if (vf.frame_id, vf.kept_id, vf.structure) != (vh.frame_id, vh.kept_id, vh.structure) {
        return Err("another pair".into());
    }
    let (bf, bh): (Vec<_>, Vec<_>) = (vf.boundaries().collect(), vh.boundaries().collect());
    if bf.len() != bh.len() {
        return Err("another boundary count".into());
    }
    let (mut flagged, mut looser) = (0u64, 0u64);
    for (k, (x, y)) in bf.iter().zip(&bh).enumerate() {
        if (x.len, x.quality) != (y.len, y.quality) {
            return Err(format!("boundary {k}: another length or quality"));
        }
        for (j, (p, q)) in x.points().zip(y.points()).enumerate() {
            if p == q {
                continue;
            }
            if p.status == Status::OverBudget && p.values.is_none() {
                flagged += 1;
                continue;
            }
            // Where the host's budget ran out, the deadline's cap on a
            // point's search (or a fold pass the clock stopped) may have
            // let the firmware finish it: any result (`process_within`'s
            // docs).
            if q.status == Status::OverBudget {
                continue;
            }
            // [X, Y, Z, z_near, z_far]: the same point, a stick holding
            // the host's.
            if let (Status::Ok, Status::Ok, Some(a), Some(b)) =
                (p.status, q.status, p.values, q.values)
            {
                if a[..3] == b[..3] && a[3] <= b[3] && a[4] >= b[4] {
                    looser += 1;
                    continue;
                }
            }
            return Err(format!(
                "boundary {k} point {j}: {:?} {:?} where the host has {:?} {:?}",
                p.status, p.values, q.status, q.values
            ));
        }
    }
    Ok((flagged, looser, vf.deadline_expired))
}
