//! The robot's state as the protocol shows and changes it: memory
//! (`readMemory`, `writeMemory`, at memory references `0x0403` or any
//! address expression), the registers and flags (`variables`,
//! `setVariable`, a value read as the monitor's `set` reads it). Each
//! change is the debugger's host action, so a step back and forward again
//! sees it at the same instruction.

use base64::Engine as _;
use serde_json::{Value, json};

use super::arguments::Arguments;
use crate::{Debugger, Expr, Register};

/// `variablesReference` of the registers and of the flags.
pub(crate) const REGISTERS: i64 = 1;
/// See [`REGISTERS`].
pub(crate) const FLAGS: i64 = 2;

/// The most bytes one `readMemory` or `writeMemory` takes: the address
/// space.
const MAX_BYTES: i64 = 0x1_0000;

/// The address `offset` bytes from the memory reference `text` (`0x0403`,
/// `$0403`, a label, any address expression), in the address space.
///
/// # Errors
/// Why it is no address, or lands outside the address space.
pub(crate) fn address(d: &Debugger, text: &str, offset: i64) -> Result<u16, String> {
    let base = d
        .symbols()
        .address(&text.trim().replace("0x", "$"))
        .map_err(|e| e.to_string())?;
    let at = i64::from(base).saturating_add(offset);
    u16::try_from(at).map_err(|_| {
        format!("${base:04X} {offset:+} is ${at:X}: outside the 6502's addresses ($0000-$FFFF)")
    })
}

/// `readMemory`.
pub(crate) fn read(d: &Debugger, args: &Arguments<'_>) -> Result<Value, String> {
    let reference = args
        .string("memoryReference")?
        .ok_or("readMemory needs `memoryReference`")?
        .replace("0x", "$");
    let base = d.symbols().address(&reference).map_err(|e| e.to_string())?;
    let offset = args.integer("offset")?.unwrap_or(0);
    let count = args.integer("count")?.unwrap_or(0).clamp(0, MAX_BYTES);
    let start = i64::from(base).saturating_add(offset);
    let end = start.saturating_add(count).min(MAX_BYTES);
    let bytes: Vec<u8> = (start.max(0)..end)
        .filter_map(|at| u16::try_from(at).ok())
        .map(|at| emulator::Bus::peek(&d.robot().robot().bus, at))
        .collect();
    let unreadable = count - i64::try_from(bytes.len()).unwrap_or(count);
    let mut body = json!({
        "address": format!("0x{:04X}", start.clamp(0, MAX_BYTES)),
        "data": base64::engine::general_purpose::STANDARD.encode(bytes),
    });
    if unreadable > 0 {
        // Outside the 6502's addresses.
        body["unreadableBytes"] = json!(unreadable);
    }
    Ok(body)
}

/// `writeMemory`: RAM only (not the ROM, the I/O page or a card's
/// registers); all of it or nothing.
pub(crate) fn write(d: &mut Debugger, args: &Arguments<'_>) -> Result<Value, String> {
    let reference = args
        .string("memoryReference")?
        .ok_or("writeMemory needs `memoryReference`")?;
    let offset = args.integer("offset")?.unwrap_or(0);
    let data = args
        .string("data")?
        .ok_or("writeMemory needs `data`, the bytes in base64")?;
    // A base64 text 4/3 the size of the address space at most.
    if data.len() > 0x1_6000 {
        return Err(format!(
            "writeMemory: {} characters of base64 are more than the 6502's 65536 addresses hold",
            data.len()
        ));
    }
    let bytes = base64::engine::general_purpose::STANDARD
        .decode(data)
        .map_err(|e| format!("writeMemory: `data` is not base64: {e}"))?;
    let start = address(d, reference, offset)?;
    d.poke(start, &bytes).map_err(|e| e.to_string())?;
    Ok(json!({"bytesWritten": bytes.len()}))
}

/// The registers ([`REGISTERS`]) or the flags ([`FLAGS`]).
pub(crate) fn variables(d: &Debugger, reference: i64) -> Vec<Value> {
    let cpu = d.cpu();
    let variable =
        |name: &str, value: String| json!({"name": name, "value": value, "variablesReference": 0});
    if reference == FLAGS {
        let p = cpu.p();
        return "NV-BDIZC"
            .chars()
            .enumerate()
            .filter(|(_, name)| *name != '-')
            .map(|(bit, name)| {
                let set = p & (0x80 >> bit) != 0;
                variable(&name.to_string(), u8::from(set).to_string())
            })
            .collect();
    }
    if reference != REGISTERS {
        return Vec::new();
    }
    vec![
        variable("PC", format!("${:04X}", cpu.pc)),
        variable("A", format!("${:02X}", cpu.a)),
        variable("X", format!("${:02X}", cpu.x)),
        variable("Y", format!("${:02X}", cpu.y)),
        variable("S", format!("${:02X}", cpu.s)),
        variable("P", format!("${:02X}", cpu.p())),
        variable("cycles", d.robot().cycles().to_string()),
    ]
}

/// `setVariable`: a register (A X Y S P PC) or a flag (N V D I Z C) set to
/// an expression's value (`$05`, `1`, a label, `A + 1`).
pub(crate) fn set(d: &mut Debugger, args: &Arguments<'_>) -> Result<Value, String> {
    let reference = args.integer("variablesReference")?.unwrap_or(0);
    let name = args
        .string("name")?
        .ok_or("setVariable needs `name`, a string")?;
    let value = args
        .string("value")?
        .ok_or("setVariable needs `value`, a string")?;
    if reference != REGISTERS && reference != FLAGS {
        return Err(format!(
            "variablesReference {reference} holds no variables: the registers are {REGISTERS}, the flags {FLAGS}"
        ));
    }
    let register = Register::named(name)
        .filter(|r| (reference == FLAGS) == matches!(r, Register::Flag(_)))
        .ok_or_else(|| {
            format!(
                "`{name}` cannot be set here: the registers are A X Y S P PC, the flags N V D I Z C"
            )
        })?;
    let parsed =
        Expr::parse(value, d.symbols()).map_err(|e| format!("{}\n{}", e.reason, e.pointed()))?;
    let number = parsed.eval(d).map_err(|e| e.to_string())?;
    d.set_register(register, number)
        .map_err(|e| e.to_string())?;
    let shown = variables(d, reference)
        .into_iter()
        .find(|v| v["name"] == register.to_string())
        .map_or(Value::Null, |v| v["value"].clone());
    Ok(json!({"value": shown}))
}
