//! `disassemble`: instructions around a memory reference, as the
//! monitor's `dis` shows them (targets named by their labels, cheap and
//! unnamed ones as the source wrote them), each with its label and its
//! source line. A 6502's instructions cannot be read backwards, so those
//! before the reference are found by decoding forward from far enough
//! before it that the decoding falls in step (as it does within a few
//! instructions) and lands on the reference exactly.

use std::path::Path;

use serde_json::{Value, json};

use crate::Debugger;
use crate::sources::Sources;

/// The most instructions one request answers: more than the address
/// space holds.
pub(crate) const MAX_INSTRUCTIONS: i64 = 0x1_0000;

/// The longest 6502 instruction, in bytes.
const LONGEST: i64 = 3;

/// How many starts are tried before the reference: decodings from
/// neighbouring bytes fall in step within a few instructions, so one of
/// the first few lands on it.
const STARTS: usize = 16;

/// `count` instructions, the first `offset` instructions from `base` (a
/// negative `offset`: before it); places outside the address space are
/// answered as the protocol asks, with invalid placeholders.
pub(crate) fn instructions(
    d: &Debugger,
    sources: &mut Sources,
    base: i64,
    offset: i64,
    count: i64,
) -> Vec<Value> {
    let count = count.clamp(0, MAX_INSTRUCTIONS);
    let offset = offset.clamp(-MAX_INSTRUCTIONS, MAX_INSTRUCTIONS);
    // The addresses of the instructions from `offset`, `None` where there
    // is no instruction (before $0000, past $FFFF, or no decoding lands).
    let mut addresses: Vec<Option<i64>> = Vec::new();
    let mut from = base;
    if offset < 0 {
        let before = usize::try_from(-offset).unwrap_or(0);
        let mut found = backwards(d, base, before);
        // Unknown ones first, then those found, the nearest last.
        addresses.extend(std::iter::repeat_n(None, before - found.len()));
        found.reverse();
        addresses.extend(found.into_iter().map(Some));
    } else {
        for _ in 0..offset {
            from = next(d, from);
        }
    }
    let total = usize::try_from(count).unwrap_or(0);
    addresses.truncate(total);
    while addresses.len() < total {
        addresses.push(Some(from));
        from = next(d, from);
    }
    let mut placeholder = base.saturating_add(offset);
    addresses
        .into_iter()
        .map(|at| {
            let shown = at.unwrap_or(placeholder);
            placeholder = shown.saturating_add(1);
            match at.and_then(|at| u16::try_from(at).ok()) {
                Some(address) => instruction(d, sources, address),
                None => json!({
                    "address": reference(shown),
                    "instruction": "??",
                    "presentationHint": "invalid",
                }),
            }
        })
        .collect()
}

/// `0x0403` (a place outside the address space as it is).
fn reference(at: i64) -> String {
    if at < 0 {
        format!("-0x{:04X}", at.unsigned_abs())
    } else {
        format!("0x{at:04X}")
    }
}

/// The address after the instruction at `at` (outside the address space:
/// the next byte).
fn next(d: &Debugger, at: i64) -> i64 {
    match u16::try_from(at) {
        Ok(address) => {
            let bus = &d.robot().robot().bus;
            let decoded = isa::Instruction::decode_with(address, |a| emulator::Bus::peek(bus, a));
            at + i64::from(decoded.len())
        }
        Err(_) => at.saturating_add(1),
    }
}

/// Up to `count` instructions just before `base`, the nearest first: from
/// the farthest start (of the first [`STARTS`] tried) that decodes forward
/// onto `base` exactly.
fn backwards(d: &Debugger, base: i64, count: usize) -> Vec<i64> {
    let reach = i64::try_from(count)
        .unwrap_or(i64::MAX)
        .saturating_mul(LONGEST);
    let lowest = base.saturating_sub(reach).max(0);
    for start in (lowest..base).take(STARTS) {
        let mut found = Vec::new();
        let mut at = start;
        while at < base {
            found.push(at);
            at = next(d, at);
        }
        if at == base {
            found.reverse();
            found.truncate(count);
            return found;
        }
    }
    Vec::new()
}

/// The instruction at `address`, as the protocol describes one.
fn instruction(d: &Debugger, sources: &mut Sources, address: u16) -> Value {
    let Some(line) = d.disassemble(address, 1).into_iter().next() else {
        return json!({"address": reference(i64::from(address)), "instruction": "??"});
    };
    let bytes: Vec<String> = line.bytes.iter().map(|b| format!("{b:02X}")).collect();
    let mut shown = json!({
        "address": reference(i64::from(address)),
        "instructionBytes": bytes.join(" "),
        "instruction": crate::monitor::named_instruction(d, sources, &line),
    });
    if let Some(label) = line
        .label
        .clone()
        .or_else(|| d.symbols().label(address).map(str::to_owned))
    {
        shown["symbol"] = json!(label);
    }
    if let Some((file, n)) = &line.source {
        shown["location"] = source(&sources.root, file);
        shown["line"] = json!(n);
    }
    shown
}

/// A `Source` for `file` (as the images name it), found from `root`.
pub(crate) fn source(root: &Path, file: &str) -> Value {
    json!({
        "name": Path::new(file).file_name().map(|n| n.to_string_lossy().into_owned()),
        "path": root.join(file).display().to_string(),
    })
}
