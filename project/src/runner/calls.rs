//! Routine-level tests (`tests/*.calls`): call a subroutine of the images
//! with registers and memory set, check what it leaves, as sim65- and
//! py65-based harnesses do. On the virtual Scorpion, so the ROM's
//! services work as on the robot.
//!
//! ```text
//! # call ROUTINE [REG=VALUE...] [ADDR=BYTES...] => [REG=VALUE...] [ADDR=BYTES...] [within N cycles]
//! call add_ab A=$01 X=$02 => A=$03 C=0
//! call clear buffer=FF FF => buffer=00 00 within 200 cycles
//! ```
//!
//! Registers are `A`, `X`, `Y` and the flags `C`, `Z`, `N`, `V`; an
//! address is `$hhhh` or a symbol of the images; bytes are hex. The call
//! is a `JSR`: it ends when the routine's `RTS` comes back.

use std::collections::HashMap;

use emulator::{Breakpoints, Stop};
use romlib::VirtualScorpion;

/// Where a call returns to: a breakpoint the routine's `RTS` lands on
/// (the bottom of the stack page: no code lives there).
const RETURN: u16 = 0x0100;
/// Cycles a call may run without `within`: a second of robot time.
const DEFAULT_LIMIT: u64 = 1_000_000;
/// The most `within` may allow: a minute of robot time, so a routine that
/// never returns ends the test in seconds, not hours.
const MAX_WITHIN: u64 = 60_000_000;

/// A register or flag.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Reg {
    A,
    X,
    Y,
    C,
    Z,
    N,
    V,
}

/// One line.
#[derive(Debug, Clone)]
pub struct Call {
    /// 1-based line.
    pub line: usize,
    /// The routine as written.
    pub routine: String,
    address: u16,
    set_regs: Vec<(Reg, u8)>,
    set_mem: Vec<(u16, Vec<u8>)>,
    want_regs: Vec<(Reg, u8)>,
    want_mem: Vec<(u16, Vec<u8>)>,
    within: Option<u64>,
}

fn reg(name: &str) -> Option<Reg> {
    Some(match name {
        "A" | "a" => Reg::A,
        "X" | "x" => Reg::X,
        "Y" | "y" => Reg::Y,
        "C" | "c" => Reg::C,
        "Z" | "z" => Reg::Z,
        "N" | "n" => Reg::N,
        "V" | "v" => Reg::V,
        _ => return None,
    })
}

fn number(text: &str) -> Option<u32> {
    if let Some(hex) = text.strip_prefix('$') {
        u32::from_str_radix(hex, 16).ok()
    } else {
        text.parse().ok()
    }
}

/// Parses a calls file against the images' symbols.
pub fn parse(text: &str, symbols: &HashMap<String, u16>) -> Result<Vec<Call>, String> {
    let mut calls = Vec::new();
    for (index, raw) in text.lines().enumerate() {
        let line = index + 1;
        let content = raw.split('#').next().unwrap_or("").trim();
        if content.is_empty() {
            continue;
        }
        let bad = |why: String| format!("line {line}: {why}");
        // `call` and the routine are words: any blanks between them.
        let rest = content
            .strip_prefix("call")
            .filter(|rest| rest.is_empty() || rest.starts_with(char::is_whitespace))
            .ok_or_else(|| bad(format!("`{content}`: a line is `call ROUTINE ... => ...`")))?;
        let (before, after) = rest.split_once("=>").unwrap_or((rest, ""));
        let mut words = before.split_whitespace();
        let routine = words
            .next()
            .ok_or_else(|| bad("no routine after `call`".into()))?;
        let settings = words.collect::<Vec<_>>().join(" ");
        let address = |name: &str| -> Result<u16, String> {
            number(name)
                .and_then(|n| u16::try_from(n).ok())
                .or_else(|| symbols.get(name).copied())
                .ok_or_else(|| {
                    bad(format!(
                        "`{name}` is neither an address nor a symbol of the images"
                    ))
                })
        };
        let target = address(routine)?;
        let mut call = Call {
            line,
            routine: routine.to_owned(),
            address: target,
            set_regs: Vec::new(),
            set_mem: Vec::new(),
            want_regs: Vec::new(),
            want_mem: Vec::new(),
            within: None,
        };
        for (side, text) in [(false, settings.as_str()), (true, after)] {
            let tokens: Vec<&str> = text.split_whitespace().collect();
            let mut i = 0;
            while i < tokens.len() {
                let token = tokens[i];
                if side && token == "within" {
                    let limit = tokens.get(i + 1).and_then(|n| number(n)).ok_or_else(|| {
                        bad("`within` needs a number of cycles: `within 200 cycles`".into())
                    })?;
                    if u64::from(limit) > MAX_WITHIN {
                        return Err(bad(format!(
                            "`within {limit}`: at most {MAX_WITHIN} cycles (a minute of robot time)"
                        )));
                    }
                    call.within = Some(u64::from(limit));
                    i += 2;
                    if tokens.get(i) == Some(&"cycles") {
                        i += 1;
                    }
                    continue;
                }
                let (name, value) = token
                    .split_once('=')
                    .ok_or_else(|| bad(format!("`{token}`: write NAME=VALUE")))?;
                if let Some(r) = reg(name) {
                    let v = number(value)
                        .and_then(|v| u8::try_from(v).ok())
                        .ok_or_else(|| bad(format!("`{value}` is not a byte")))?;
                    if side {
                        &mut call.want_regs
                    } else {
                        &mut call.set_regs
                    }
                    .push((r, v));
                    i += 1;
                    continue;
                }
                let at = address(name)?;
                let mut bytes = vec![
                    u8::from_str_radix(value, 16)
                        .map_err(|_| bad(format!("`{value}` is not a hex byte")))?,
                ];
                i += 1;
                while let Some(next) = tokens
                    .get(i)
                    .filter(|t| !t.contains('=') && **t != "within")
                {
                    bytes.push(
                        u8::from_str_radix(next, 16)
                            .map_err(|_| bad(format!("`{next}` is not a hex byte")))?,
                    );
                    i += 1;
                }
                if usize::from(at) + bytes.len() > 0x1_0000 {
                    return Err(bad(format!(
                        "{} bytes from ${at:04X} run past $FFFF",
                        bytes.len()
                    )));
                }
                if side {
                    &mut call.want_mem
                } else {
                    &mut call.set_mem
                }
                .push((at, bytes));
            }
        }
        calls.push(call);
    }
    if calls.is_empty() {
        return Err("the file has no call in it, so it would check nothing".into());
    }
    Ok(calls)
}

fn flag(p: u8, r: Reg) -> u8 {
    let bit = match r {
        Reg::C => 0x01,
        Reg::Z => 0x02,
        Reg::V => 0x40,
        _ => 0x80,
    };
    u8::from(p & bit != 0)
}

/// Runs one call on `robot` (a fresh one, images loaded).
pub fn run(call: &Call, robot: &mut VirtualScorpion) -> Result<(), String> {
    let machine = robot.robot_mut();
    for (at, bytes) in &call.set_mem {
        machine
            .board_mut()
            .load(*at, bytes)
            .map_err(|e| format!("cannot set ${at:04X}: {e}"))?;
    }
    let cpu = &mut machine.cpu;
    let mut p = cpu.p();
    for (r, v) in &call.set_regs {
        match r {
            Reg::A => cpu.a = *v,
            Reg::X => cpu.x = *v,
            Reg::Y => cpu.y = *v,
            flag_reg => {
                let bit = match flag_reg {
                    Reg::C => 0x01,
                    Reg::Z => 0x02,
                    Reg::V => 0x40,
                    _ => 0x80,
                };
                p = if *v != 0 { p | bit } else { p & !bit };
            }
        }
    }
    cpu.set_p(p);
    // A JSR from RETURN: push RETURN - 1, jump.
    let [high, low] = (RETURN - 1).to_be_bytes();
    let s = cpu.s;
    cpu.s = s.wrapping_sub(2);
    let start = machine.now();
    machine
        .board_mut()
        .load(0x0100 + u16::from(s), &[high])
        .and_then(|()| {
            machine
                .board_mut()
                .load(0x0100 + u16::from(s.wrapping_sub(1)), &[low])
        })
        .map_err(|e| format!("cannot push the return address: {e}"))?;
    machine.cpu.pc = call.address;
    // A profiler set on the robot sees the call as a JSR's.
    robot.entered(call.address, s);
    let limit = call.within.unwrap_or(DEFAULT_LIMIT);
    let mut stop_at = Breakpoints::new();
    stop_at.insert(RETURN);
    // Through the robot's runner: a profiler or a coverage count set on
    // it sees the call.
    let stop = robot.run_to(start + limit + 1, &mut stop_at);
    let machine = robot.robot_mut();
    let took = machine.now() - start;
    match stop {
        Stop::Hook { pc } if pc == RETURN => {}
        Stop::Jam { pc, opcode } => {
            return Err(format!("the CPU jammed at ${pc:04X} (${opcode:02X})"));
        }
        _ => {
            let pc = machine.cpu.pc;
            // A hook handler ends by jumping into the ROM (`jmp CMD_DONE`),
            // never with an `RTS` back to its caller: say so where it is.
            let why = if pc >= platform::map::ROM_START {
                ": it is in the ROM, and a routine that ends by jumping there \
                 (a handler's `jmp CMD_DONE`) never returns to a `call`; call \
                 the subroutines it uses, or test the handler with a transcript"
            } else {
                ""
            };
            return Err(format!(
                "`{}` did not return within {limit} cycles (PC ${pc:04X}{why})",
                call.routine
            ));
        }
    }
    if let Some(within) = call.within
        && took > within
    {
        return Err(format!(
            "`{}` took {took} cycles, more than {within}",
            call.routine
        ));
    }
    let mut wrong = Vec::new();
    let cpu = &machine.cpu;
    for (r, want) in &call.want_regs {
        let got = match r {
            Reg::A => cpu.a,
            Reg::X => cpu.x,
            Reg::Y => cpu.y,
            other => flag(cpu.p(), *other),
        };
        if got != *want {
            wrong.push(format!("{r:?}=${got:02X}, expected ${want:02X}"));
        }
    }
    let memory = machine.board().memory();
    for (at, want) in &call.want_mem {
        let got: Vec<u8> = (0..want.len())
            .map(|i| memory[usize::from(at.wrapping_add(i as u16))])
            .collect();
        if got != *want {
            let hex = |b: &[u8]| {
                b.iter()
                    .map(|x| format!("{x:02X}"))
                    .collect::<Vec<_>>()
                    .join(" ")
            };
            wrong.push(format!("${at:04X}: {}, expected {}", hex(&got), hex(want)));
        }
    }
    if wrong.is_empty() {
        Ok(())
    } else {
        Err(format!("after {took} cycles: {}", wrong.join("; ")))
    }
}

#[cfg(test)]
mod tests;
