//! `cargo xtask size`: the footprint of the size probes on the three thumb targets.
//!
//! Each probe (`tests/qemu/src/bin/size_probe*.rs`) is built in release (opt-level "s", fat LTO,
//! as `tests/qemu/Cargo.toml` sets). `.text` and `.rodata` come from `arm-none-eabi-size -A`,
//! the breakdown of `.text` by origin from `arm-none-eabi-nm -S`. The stack is measured on
//! target, by running the very binary that was sized: QEMU starts with the probe's free RAM
//! (from `_stack_end` up to `_stack_start`) painted with a pattern by a generic loader device,
//! the probe runs its workload and then sets its `PROBE_DONE` word, and the RAM is read back
//! over QMP (`memsave`: the CPU's view; the nRF51 maps its SRAM outside QEMU's system memory); the stack used is the distance from the top of RAM down to the lowest word whose
//! paint was overwritten. The probes carry no measuring code beyond that one store.
//!
//! Output: the human tables, then as the last line one JSON object
//! `{"<target>": {"<probe>": {"text": N, "rodata": N, "bss": N, "stack": N}}}` (bytes).

use crate::{cargo, elf, run, TARGETS};
use raykernel::bvh::{nodes_needed, BuildOptions, BuilderKind};
use raykernel::{Bvh, Node, Triangle};
use std::io::{BufRead, BufReader, Write};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// One size probe: its name in the JSON object, its binary, and what it links.
struct Probe {
    name: &'static str,
    bin: &'static str,
    what: &'static str,
}

const PROBES: [Probe; 3] = [
    Probe {
        name: "build_traverse",
        bin: "size_probe",
        what: "f32 SAH BVH build over a generated 32-triangle mesh, then closest-hit and any-hit queries",
    },
    Probe {
        name: "render_bvh",
        bin: "size_probe_render",
        what: "the default scene in f32, a SAH BVH per object without reinsertion (`BvhFamily<StaticBuild<Sah, false>>`), the renderer's parts the scene uses (`RenderFeatures`): scene conversion, `Renderer::with_features`, one row of sRGB pixels (the scene's buffers in statics, `.bss`)",
    },
    Probe {
        name: "traverse_baked",
        bin: "size_probe_baked",
        what: "an f32 binary BVH baked on the host (`tests/golden/baked_ico.bvh`, 320 triangles, its bytes in `.rodata`) loaded in place with every check, then closest-hit and any-hit queries; no builder",
    },
];

/// The pattern the free RAM is painted with (as in `tests/qemu/src/lib.rs`).
const PAINT: u32 = 0xa5c3_5a3c;
/// The value a probe stores in `PROBE_DONE` when its workload has run ("DONE").
const DONE: u32 = 0x444f_4e45;
/// How long a probe may run under QEMU before the measurement gives up.
const PROBE_TIMEOUT: Duration = Duration::from_secs(60);
/// Largest symbols listed per probe and target.
const TOP_SYMBOLS: usize = 8;

/// What one probe measured on one target.
#[derive(Default)]
struct Footprint {
    text: u64,
    rodata: u64,
    bss: u64,
    stack: Option<u64>,
    parts: Parts,
    largest: Vec<(u64, String)>,
}

/// `.text` bytes by origin.
#[derive(Default)]
struct Parts {
    /// Compiler builtins (soft-float, memcpy and friends).
    builtins: u64,
    /// Of `builtins`, the `f64` soft-float routines.
    soft_f64: u64,
    libm: u64,
    /// Everything else: kernel code (mostly inlined into the probe), core, startup.
    rest: u64,
}

/// A symbol from `arm-none-eabi-nm -S -C`: address, size (0 if nm gives none), type, name.
struct Symbol {
    addr: u64,
    size: u64,
    kind: char,
    name: String,
}

fn symbols(elf: &Path) -> Option<Vec<Symbol>> {
    let out = Command::new("arm-none-eabi-nm")
        .args(["-S", "-C"])
        .arg(elf)
        .output()
        .ok()?;
    if !out.status.success() {
        return None;
    }
    let text = String::from_utf8_lossy(&out.stdout);
    let hex = |s: &str| u64::from_str_radix(s, 16).ok();
    let mut list = Vec::new();
    for line in text.lines() {
        // "addr size kind name" or "addr kind name"; demangled names may contain spaces.
        let Some((addr, rest)) = line.split_once(' ') else {
            continue;
        };
        let Some((second, rest)) = rest.split_once(' ') else {
            continue;
        };
        let (size, kind, name) = if second.len() == 1 {
            (Some(0), second, rest)
        } else {
            let Some((kind, name)) = rest.split_once(' ') else {
                continue;
            };
            (hex(second), kind, name)
        };
        let (Some(addr), Some(size), Some(kind)) = (hex(addr), size, kind.chars().next()) else {
            continue;
        };
        list.push(Symbol {
            addr,
            size,
            kind,
            name: name.to_string(),
        });
    }
    Some(list)
}

/// `(.text, .rodata, .bss)` of an ELF, from `arm-none-eabi-size -A`.
fn sections(elf: &Path) -> Option<(u64, u64, u64)> {
    let out = Command::new("arm-none-eabi-size")
        .arg("-A")
        .arg(elf)
        .output()
        .ok()?;
    let text = String::from_utf8_lossy(&out.stdout);
    let get = |name: &str| {
        text.lines()
            .find(|l| l.split_whitespace().next() == Some(name))
            .and_then(|l| l.split_whitespace().nth(1)?.parse().ok())
    };
    Some((get(".text")?, get(".rodata")?, get(".bss")?))
}

/// True for the compiler-builtins routines of `f64` arithmetic and conversions.
fn is_soft_f64(name: &str) -> bool {
    const MARKS: [&str; 12] = [
        "__aeabi_d",
        "__aeabi_f2d",
        "__aeabi_i2d",
        "__aeabi_ui2d",
        "__aeabi_l2d",
        "__aeabi_ul2d",
        "df3",
        "df2",
        "dfsi",
        "dfdi",
        "extendsfdf",
        "truncdfsf",
    ];
    MARKS.iter().any(|m| name.contains(m)) || name.contains("sidf") || name.contains("didf")
}

fn parts(syms: &[Symbol]) -> Parts {
    let mut p = Parts::default();
    for s in syms.iter().filter(|s| s.kind.eq_ignore_ascii_case(&'t')) {
        let name = s.name.as_str();
        if name.starts_with("compiler_builtins") || name.starts_with("__aeabi") {
            p.builtins += s.size;
            if is_soft_f64(name) {
                p.soft_f64 += s.size;
            }
        } else if name.starts_with("libm") {
            p.libm += s.size;
        } else {
            p.rest += s.size;
        }
    }
    p
}

fn largest(syms: &[Symbol]) -> Vec<(u64, String)> {
    let mut v: Vec<(u64, String)> = syms
        .iter()
        .filter(|s| s.kind.eq_ignore_ascii_case(&'t') && s.size > 0)
        .map(|s| (s.size, s.name.clone()))
        .collect();
    v.sort_by(|a, b| b.0.cmp(&a.0).then_with(|| a.1.cmp(&b.1)));
    v.truncate(TOP_SYMBOLS);
    v
}

/// Runs `elf` under QEMU with its free RAM painted and returns the bytes of stack it used.
fn measure_stack(machine: &str, cpu: &str, elf: &Path, syms: &[Symbol]) -> Result<u64, String> {
    let addr = |name: &str| {
        syms.iter()
            .find(|s| s.name == name)
            .map(|s| s.addr)
            .ok_or_else(|| format!("no symbol {name} in {}", elf.display()))
    };
    let (bottom, top, done) = (
        addr("_stack_end")?,
        addr("_stack_start")?,
        addr("PROBE_DONE")?,
    );
    // `PROBE_DONE` lives in .bss, below the stack.
    if !(bottom < top && bottom % 4 == 0 && top % 4 == 0 && done + 4 <= bottom) {
        return Err(format!(
            "unexpected layout: stack {bottom:#x}..{top:#x}, PROBE_DONE at {done:#x}"
        ));
    }
    let len = top - bottom;
    let paint_file = elf.with_extension("paint");
    let dump_file = elf.with_extension("ram");
    let paint: Vec<u8> = (0..len / 4).flat_map(|_| PAINT.to_le_bytes()).collect();
    std::fs::write(&paint_file, paint)
        .map_err(|e| format!("write {}: {e}", paint_file.display()))?;
    let _ = std::fs::remove_file(&dump_file);
    let mut qemu = Command::new("qemu-system-arm")
        .args(["-machine", machine, "-cpu", cpu])
        .args([
            "-display", "none", "-monitor", "none", "-serial", "none", "-qmp", "stdio",
        ])
        .arg("-kernel")
        .arg(elf)
        .arg("-device")
        .arg(format!(
            "loader,file={},addr={bottom:#x},force-raw=on",
            paint_file.display()
        ))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .map_err(|e| format!("cannot run qemu-system-arm: {e}"))?;
    let result = qmp_session(&mut qemu, bottom, top, done, &dump_file);
    let _ = qemu.kill();
    let _ = qemu.wait();
    let _ = std::fs::remove_file(&paint_file);
    result
}

/// Talks QMP to a running probe: polls its RAM until `PROBE_DONE` is set, then scans the paint.
fn qmp_session(
    qemu: &mut std::process::Child,
    bottom: u64,
    top: u64,
    done: u64,
    dump_file: &Path,
) -> Result<u64, String> {
    let (Some(mut input), Some(output)) = (qemu.stdin.take(), qemu.stdout.take()) else {
        return Err("no QMP pipes".into());
    };
    let mut output = BufReader::new(output);
    // Replies to commands start with {"return" or {"error"; the greeting and events are skipped.
    let mut command = |json: String| -> Result<(), String> {
        writeln!(input, "{json}").map_err(|e| format!("QMP write: {e}"))?;
        loop {
            let mut line = String::new();
            if output
                .read_line(&mut line)
                .map_err(|e| format!("QMP read: {e}"))?
                == 0
            {
                return Err("QEMU closed QMP".into());
            }
            if line.starts_with("{\"return\"") {
                return Ok(());
            }
            if line.starts_with("{\"error\"") {
                return Err(format!("QMP: {}", line.trim()));
            }
        }
    };
    command(r#"{"execute": "qmp_capabilities"}"#.into())?;
    let start = Instant::now();
    // The dump covers the probe's `PROBE_DONE` word (in .bss, below the stack) and the stack.
    let from = done.min(bottom);
    let save = format!(
        r#"{{"execute": "memsave", "arguments": {{"val": {from}, "size": {}, "filename": "{}"}}}}"#,
        top - from,
        dump_file.display()
    );
    loop {
        command(save.clone())?;
        let ram =
            std::fs::read(dump_file).map_err(|e| format!("read {}: {e}", dump_file.display()))?;
        let word = |a: u64| {
            let i = (a - from) as usize;
            ram.get(i..i + 4)
                .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        };
        if word(done) == Some(DONE) {
            let mut a = bottom;
            while a < top && word(a) == Some(PAINT) {
                a += 4;
            }
            let _ = command(r#"{"execute": "quit"}"#.into());
            return if a == bottom {
                Err("the stack reached the end of its painted region".into())
            } else {
                Ok(top - a)
            };
        }
        if start.elapsed() > PROBE_TIMEOUT {
            return Err(format!("probe did not finish within {PROBE_TIMEOUT:?}"));
        }
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// Builds, sizes and runs one probe on one target.
fn footprint(target: &str, machine: &str, cpu: &str, probe: &Probe) -> Result<Footprint, String> {
    // Without the suites' default features: the probes link what a firmware renderer that
    // names no optional kernel feature links (no path integrator).
    let args = [
        "build",
        "--release",
        "--no-default-features",
        "--bin",
        probe.bin,
        "--target",
        target,
    ];
    if !run(cargo(&args)).0 {
        return Err(format!("build of {} for {target} failed", probe.bin));
    }
    let path = elf(target, "release", probe.bin);
    let (text, rodata, bss) = sections(&path).ok_or("arm-none-eabi-size failed")?;
    let syms = symbols(&path).ok_or("arm-none-eabi-nm failed")?;
    let stack = measure_stack(machine, cpu, &path, &syms);
    if let Err(e) = &stack {
        println!("{}: stack not measured: {e}", probe.name);
    }
    Ok(Footprint {
        text,
        rodata,
        bss,
        stack: stack.ok(),
        parts: parts(&syms),
        largest: largest(&syms),
    })
}

/// Arena bytes (nodes in use + primitive ids) per triangle for each builder, leaves of up to 4.
fn arena_per_tri(tris: &[Triangle<f32>]) -> Vec<(BuilderKind, f64)> {
    let mut out = Vec::new();
    for builder in BuilderKind::ALL {
        let mut nodes = vec![Node::<f32>::EMPTY; nodes_needed(tris.len())];
        let mut ids = vec![0u32; tris.len()];
        let options = BuildOptions {
            builder,
            max_leaf_size: 4,
            reinsertion: true,
        };
        if let Ok(bvh) = Bvh::build(tris, &mut nodes, &mut ids, options) {
            out.push((builder, bvh.bytes_used() as f64 / tris.len() as f64));
        }
    }
    out
}

/// A 64×64 heightfield (8192 triangles) of a smooth bump: a larger generated mesh.
fn heightfield() -> Vec<Triangle<f32>> {
    const N: usize = 64;
    let h = |i: usize, j: usize| {
        let (x, y) = (i as f32 / N as f32 - 0.5, j as f32 / N as f32 - 0.5);
        libm::cosf(6.0 * x) * libm::sinf(5.0 * y)
    };
    let p = |i: usize, j: usize| [i as f32, j as f32, 8.0 * h(i, j)];
    let mut out = Vec::with_capacity(2 * N * N);
    for i in 0..N {
        for j in 0..N {
            out.push(Triangle {
                v: [p(i, j), p(i + 1, j), p(i, j + 1)],
            });
            out.push(Triangle {
                v: [p(i + 1, j), p(i + 1, j + 1), p(i, j + 1)],
            });
        }
    }
    out
}

/// The JSON object of the last output line.
fn json(results: &[(&str, Vec<(&str, &Footprint)>)]) -> String {
    let targets: Vec<String> = results
        .iter()
        .map(|(target, probes)| {
            let probes: Vec<String> = probes
                .iter()
                .map(|(name, f)| {
                    let stack = f
                        .stack
                        .map_or_else(|| "null".to_string(), |s| s.to_string());
                    format!(
                        r#""{name}": {{"text": {}, "rodata": {}, "bss": {}, "stack": {stack}}}"#,
                        f.text, f.rodata, f.bss
                    )
                })
                .collect();
            format!(r#""{target}": {{{}}}"#, probes.join(", "))
        })
        .collect();
    format!("{{{}}}", targets.join(", "))
}

pub fn size() -> bool {
    let mut ok = true;
    let mut all: Vec<(&str, &str, Vec<Footprint>)> = Vec::new();
    for (target, core, machine, cpu) in TARGETS {
        if !target.starts_with("thumb") {
            continue;
        }
        println!("\n=== {core} ({target}) ===");
        let mut row = Vec::new();
        for probe in &PROBES {
            match footprint(target, machine, cpu, probe) {
                Ok(f) => {
                    ok &= f.stack.is_some();
                    row.push(f);
                }
                Err(e) => {
                    println!("{}: {e}", probe.name);
                    ok = false;
                    row.push(Footprint::default());
                }
            }
        }
        all.push((target, core, row));
    }

    println!("\n## Footprint (generated by `cargo xtask size`)\n");
    println!("Release, opt-level \"s\", fat LTO. Stack: measured on target under QEMU (RAM painted before reset, read back once the probe is done), arrays the probe keeps on the stack included; its statics are `.bss`.\n");
    for (i, probe) in PROBES.iter().enumerate() {
        println!(
            "`{}` (`tests/qemu/src/bin/{}.rs`): {}.\n",
            probe.name, probe.bin, probe.what
        );
        println!("| core | .text B | builtins (of which f64 soft-float) / libm / kernel, core, startup | .rodata B | .bss B | stack B |");
        println!("|---|---:|---:|---:|---:|---:|");
        for (target, core, row) in &all {
            let f = &row[i];
            let p = &f.parts;
            println!(
                "| {core} (`{target}`) | {} | {} ({}) / {} / {} | {} | {} | {} |",
                f.text,
                p.builtins,
                p.soft_f64,
                p.libm,
                p.rest,
                f.rodata,
                f.bss,
                f.stack.map_or_else(|| "?".to_string(), |s| s.to_string())
            );
        }
        println!();
        for (target, _, row) in &all {
            println!("Largest `.text` symbols of `{}` on `{target}`:", probe.name);
            for (size, name) in &row[i].largest {
                let name: String = name.chars().take(100).collect();
                println!("    {size:>6} B  {name}");
            }
        }
        println!();
    }

    let mut ico = crate::cases::empty_mesh::<f32>();
    ok &= crate::cases::icosphere(&mut ico).is_ok();
    let field = heightfield();
    println!("Arena bytes per triangle (nodes in use + primitive ids; `nodes_needed` reserves 68 B/tri), leaves of up to 4:\n");
    println!("| mesh | triangles | sah | median | midpoint |");
    println!("|---|---:|---:|---:|---:|");
    for (name, tris) in [
        ("icosphere level 1", &ico[..]),
        ("64×64 heightfield", &field[..]),
    ] {
        let v = arena_per_tri(tris);
        ok &= v.len() == 3;
        let cells: Vec<String> = v.iter().map(|(_, b)| format!("{b:.1}")).collect();
        println!("| {name} | {} | {} |", tris.len(), cells.join(" | "));
    }
    println!(
        "\nTraversal stack: MAX_DEPTH × 8 = {} B reserved per query.\n",
        raykernel::bvh::MAX_DEPTH * 8
    );

    let results: Vec<(&str, Vec<(&str, &Footprint)>)> = all
        .iter()
        .map(|(target, _, row)| {
            (
                *target,
                PROBES.iter().map(|p| p.name).zip(row.iter()).collect(),
            )
        })
        .collect();
    println!("{}", json(&results));
    ok
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_has_one_object_per_target_and_probe() {
        let f = Footprint {
            text: 10,
            rodata: 2,
            bss: 4,
            stack: Some(300),
            ..Footprint::default()
        };
        let g = Footprint::default();
        let results = vec![("t1", vec![("a", &f), ("b", &g)])];
        assert_eq!(
            json(&results),
            r#"{"t1": {"a": {"text": 10, "rodata": 2, "bss": 4, "stack": 300}, "b": {"text": 0, "rodata": 0, "bss": 0, "stack": null}}}"#
        );
    }

    #[test]
    fn soft_float_names_are_recognised() {
        for name in [
            "__aeabi_dmul",
            "__aeabi_f2d",
            "compiler_builtins::float::div::__divdf3",
            "__aeabi_d2f",
        ] {
            assert!(is_soft_f64(name), "{name}");
        }
        for name in [
            "__aeabi_fmul",
            "__aeabi_memcpy",
            "compiler_builtins::float::div::__divsf3",
        ] {
            assert!(!is_soft_f64(name), "{name}");
        }
    }
}
