//! The firmware's disassembly as a map: every instruction by address, with
//! its function, innermost source line, class in the cycle model and
//! fall-through address (`llvm-objdump -d -l -C`).

use std::collections::BTreeMap;
use std::path::Path;

use crate::cycles::{classify, Class};
use crate::util::{capture, tool};

/// One instruction of the firmware's disassembly.
pub struct Insn {
    /// The (not inlined) function it belongs to, without the hash.
    pub func: String,
    /// Its innermost source line (`file.rs:line`), inlined code included.
    pub line: String,
    /// Mnemonic and operands, single-spaced.
    pub text: String,
    /// Its class in the cycle model.
    pub class: Class,
    /// The address after it (where execution falls through).
    pub fall_through: u64,
}

/// The firmware's code: every instruction by address, and the address of
/// `profile::marker`.
pub struct Disassembly {
    pub code: BTreeMap<u64, Insn>,
    pub marker: u64,
}

/// The disassembly (`llvm-objdump -d -l -C`): address -> (function, source
/// line, instruction), and where `profile::marker` starts.
pub fn disassemble(elf: &Path) -> Result<Disassembly, String> {
    let text = capture(
        &tool("llvm-objdump")?,
        &[
            "-d",
            "-l",
            "-C",
            "--no-show-raw-insn",
            &elf.to_string_lossy(),
        ],
    )?;
    let mut code = BTreeMap::new();
    let (mut func, mut line) = (String::new(), String::new());
    let mut marker = None;
    for l in text.lines() {
        if let Some(name) = l.strip_suffix(">:").and_then(|h| h.split_once(" <")) {
            func = strip_hash(name.1);
            line.clear();
            if func == "profile::marker" {
                marker = u64::from_str_radix(name.0.trim(), 16).ok();
            }
        } else if let Some(src) = l.strip_prefix("; ").filter(|s| s.contains(".rs:")) {
            line = short_path(src);
        } else if let Some((a, insn)) = l.trim_start().split_once(':') {
            if let Ok(addr) = u64::from_str_radix(a.trim(), 16) {
                let text = insn.split_whitespace().collect::<Vec<_>>().join(" ");
                code.insert(
                    addr,
                    Insn {
                        func: func.clone(),
                        line: line.clone(),
                        class: classify(&text),
                        text,
                        // Thumb-2 instructions are 2 or 4 bytes: the next
                        // address in the listing, filled in below.
                        fall_through: addr + 4,
                    },
                );
            }
        }
    }
    let marker = marker.ok_or("no profile::marker in the disassembly")?;
    let addrs: Vec<u64> = code.keys().copied().collect();
    for w in addrs.windows(2) {
        if let Some(i) = code.get_mut(&w[0]) {
            i.fall_through = w[1];
        }
    }
    Ok(Disassembly { code, marker })
}

/// A demangled symbol without its `::h…` hash (and the legacy mangling's
/// `$LT$`/`$GT$` escapes undone).
fn strip_hash(name: &str) -> String {
    let name = match name.rsplit_once("::h") {
        Some((head, hash)) if hash.len() == 16 && hash.chars().all(|c| c.is_ascii_hexdigit()) => {
            head
        }
        _ => name,
    };
    name.replace("$LT$", "<").replace("$GT$", ">")
}

/// `…/src/x.rs:12` or `…/library/core/src/y.rs:34` without the prefix.
fn short_path(src: &str) -> String {
    for cut in ["/library/", "/src/bin/", "/src/"] {
        if let Some((_, tail)) = src.rsplit_once(cut) {
            return if cut == "/src/bin/" {
                format!("bin/{tail}")
            } else {
                tail.to_string()
            };
        }
    }
    src.to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_paths_shortened() {
        assert_eq!(
            strip_hash("roadstereo::processor::pass2_lean::h612ca9db6e238ab5"),
            "roadstereo::processor::pass2_lean"
        );
        assert_eq!(
            strip_hash("roadstereo::epipolar::IndexedSearch$LT$_$GT$::prepare"),
            "roadstereo::epipolar::IndexedSearch<_>::prepare"
        );
        assert_eq!(short_path("/tmp/x/src/math.rs:188"), "math.rs:188");
        assert_eq!(
            short_path("/tmp/x/src/bin/profile.rs:60"),
            "bin/profile.rs:60"
        );
        assert_eq!(
            short_path("/rustc/5980/library/core/src/slice/index.rs:219"),
            "core/src/slice/index.rs:219"
        );
    }
}
