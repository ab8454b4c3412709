//! The measurements behind README's worst-case formula ("Worst case"):
//! every 2 × 256 member of the adversarial family and every probe under a
//! sweep of work budgets (`xtask/src/worst.rs` fits the envelope).

use roadstereo::{Config, Frame, Processor, Status};

use super::pairs::{camera1, cut, member_config, pair_data, probes};
use super::{load, measure_pair, ADVERSARIAL, BENCH, CAP};

/// Budgets of the configuration probes (the sweep's, up to twice the
/// default: the probes' frames are long), with the small budgets just
/// above the smallest (a fifth review found a pair over the envelope at
/// `w = 9`, none of the sweep's then, a unit there dearer than the
/// sweep's slopes).
const PROBE_SWEEP: [u32; 7] = [
    Config::MIN_WORK_PER_POINT,
    9,
    10,
    12,
    16,
    Config::DEFAULT_WORK_PER_POINT,
    160,
];

/// Budgets of the work sweep, units per point: the smallest accepted, two
/// between, the default and up to 8 times it.
const SWEEP: [u32; 6] = [
    Config::MIN_WORK_PER_POINT,
    16,
    40,
    Config::DEFAULT_WORK_PER_POINT,
    160,
    640,
];

/// One row of the worst-case sweep: the pair under error model `errors`
/// ([`member_config`]) with budget `w`, measured and logged under `name`
/// (the family's `n`); false when the configuration is not valid.
fn sweep_row(
    processor: &mut Processor<CAP, 2>,
    (f1, f2, m): (&Frame<CAP, 2>, &Frame<CAP, 2>, &roadstereo::Motion),
    (name, n): (&str, u32),
    errors: u8,
    w: u32,
) -> bool {
    let Some(c) = member_config(errors, w) else {
        return false;
    };
    processor.set_config(c);
    let r = measure_pair(processor, f1, f2, m);
    let s = processor.structure();
    defmt::info!(
        "sweep name={=str} n={=u32} w={=u32} points={=u32} instr={=u32} processed={=bool} work_spent={=u32} over_budget={=usize}",
        name,
        n,
        w,
        r.points,
        r.instr,
        r.processed,
        s.work_units().0,
        s.status_counts().get(Status::OverBudget)
    );
    true
}

/// The measurements behind README's worst-case formula ("Worst case"):
/// the fixed cost of a frame (one and two boundaries of two points each,
/// from the N = 32 bench pair), and every 2 × 256 member of the adversarial
/// family under each budget of [`SWEEP`] (instructions against the work
/// units spent; the points flagged `over_budget`).
pub fn worst_case_sweep(
    processor: &mut Processor<CAP, 2>,
    f1: &mut Frame<CAP, 2>,
    f2: &mut Frame<CAP, 2>,
) {
    defmt::info!(
        "work default_per_point={=u32}",
        Config::DEFAULT_WORK_PER_POINT
    );
    if let Some((_, data)) = BENCH.first() {
        if let Some(m) = load(data, f1, f2) {
            for b in 1..=2usize {
                let (t1, t2, pushed) = cut((f1, f2), b, (0, 2));
                let r = measure_pair(processor, &t1, &t2, &m);
                defmt::info!(
                    "fixed boundaries={=usize} points={=u32} instr={=u32} processed={=bool} pushed={=bool}",
                    b,
                    r.points,
                    r.instr,
                    r.processed,
                    pushed
                );
            }
        }
    }
    for (name, n, errors, data) in ADVERSARIAL.iter().filter(|a| a.1 == 256) {
        let Some(m) = load(data, f1, f2) else {
            continue;
        };
        for w in SWEEP {
            sweep_row(processor, (f1, f2, &m), (name, *n), *errors, w);
        }
    }
    for (probe, member, n, errors, window) in probes() {
        let Some(data) = pair_data(member, n) else {
            defmt::error!(
                "no member {=str} n={=u32} for probe {=str}",
                member,
                n,
                probe
            );
            continue;
        };
        let Some(m) = load(data, f1, f2) else {
            continue;
        };
        if !camera1(member, f1) {
            defmt::error!("probe {=str}: its frame-1 camera does not push", probe);
            continue;
        }
        if let Some((off, k)) = window {
            let (t1, t2, pushed) = cut((f1, f2), 2, (off, off + k));
            if !pushed {
                defmt::error!("probe {=str}: its window does not push", probe);
                continue;
            }
            (*f1, *f2) = (t1, t2);
        }
        for w in PROBE_SWEEP {
            if !sweep_row(processor, (f1, f2, &m), (probe, n), errors, w) {
                defmt::error!("bad probe configuration for {=str}", probe);
            }
        }
    }
    processor.set_config(Config::DEFAULT);
}
