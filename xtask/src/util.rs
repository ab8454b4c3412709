//! Running programs and finding the tools: the repository root, the pinned
//! toolchain, commands echoed and checked, output captured.

use std::path::{Path, PathBuf};
use std::process::Command;

pub const TOOLCHAIN: &str = "1.95.0";
pub const THUMB: &str = "thumbv7em-none-eabihf";

pub fn root() -> PathBuf {
    // xtask/ lives directly under the repository root.
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."))
}

pub fn run(dir: &Path, program: &str, args: &[&str]) -> Result<(), String> {
    println!("xtask: ({}) {} {}", dir.display(), program, args.join(" "));
    let status = Command::new(program)
        .args(args)
        .current_dir(dir)
        .status()
        .map_err(|e| format!("cannot start {program}: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("`{program} {}` failed ({status})", args.join(" ")))
    }
}

pub fn have(program: &str, arg: &str) -> bool {
    Command::new(program)
        .arg(arg)
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false)
}

pub fn tool(name: &str) -> Result<PathBuf, String> {
    let out = Command::new("rustc")
        .args(["--print", "sysroot"])
        .current_dir(root())
        .output()
        .map_err(|e| format!("rustc: {e}"))?;
    let sysroot = PathBuf::from(String::from_utf8_lossy(&out.stdout).trim());
    let host = Command::new("rustc")
        .args(["-vV"])
        .output()
        .map_err(|e| format!("rustc: {e}"))?;
    let triple = String::from_utf8_lossy(&host.stdout)
        .lines()
        .find_map(|l| l.strip_prefix("host: ").map(str::to_string))
        .ok_or("cannot find the host triple")?;
    Ok(sysroot
        .join("lib/rustlib")
        .join(triple)
        .join("bin")
        .join(name))
}

pub fn capture(program: &Path, args: &[&str]) -> Result<String, String> {
    let out = Command::new(program)
        .args(args)
        .output()
        .map_err(|e| format!("{}: {e}", program.display()))?;
    if !out.status.success() {
        return Err(format!("{} failed", program.display()));
    }
    Ok(String::from_utf8_lossy(&out.stdout).to_string())
}
