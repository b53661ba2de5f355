//! The requests that set breakpoints: by source line (`setBreakpoints`),
//! by label (`setFunctionBreakpoints`), by address
//! (`setInstructionBreakpoints`) and on memory (`dataBreakpointInfo`,
//! `setDataBreakpoints`). Places, conditions, hit counts and log messages
//! are read as the monitor reads them (`break PLACE if COND hits N log
//! MESSAGE`): one interpreter for both front ends. A request whose
//! arguments have the wrong shape is refused whole and changes nothing; a
//! breakpoint that cannot be set (no code on its line, a condition that
//! does not read) is answered unverified with the reason.

use serde_json::{Value, json};

use super::arguments::Arguments;
use super::points::{Kind, Points, What};
use crate::monitor::breaks;
use crate::{Breakpoint, Debugger, Expr, HitCondition, PointOptions, Template, Watch, WatchKind};

/// One breakpoint asked for: where, with what, or why it cannot be set.
type Wanted = Result<(What, Option<u16>), String>;

/// A breakpoint's `condition`, `hitCondition` and `logMessage` (the
/// latter only where `log` says), or why they do not read; the outer
/// error for arguments of the wrong type.
fn options(
    d: &Debugger,
    a: &Arguments<'_>,
    log: bool,
) -> Result<Result<PointOptions, String>, String> {
    let condition = a.string("condition")?.filter(|t| !t.trim().is_empty());
    let hits = a.string("hitCondition")?.filter(|t| !t.trim().is_empty());
    let message = if log { a.string("logMessage")? } else { None };
    let mut options = PointOptions::default();
    if let Some(text) = condition {
        match Expr::parse(text, d.symbols()) {
            Ok(parsed) => options.condition = Some(parsed),
            Err(e) => return Ok(Err(format!("condition: {}\n{}", e.reason, e.pointed()))),
        }
    }
    if let Some(text) = hits {
        match HitCondition::parse(text) {
            Ok(parsed) => options.hits = Some(parsed),
            Err(e) => return Ok(Err(format!("hit count: {e} (N, >= N, == N or % N)"))),
        }
    }
    if let Some(text) = message {
        match Template::parse(text, d.symbols()) {
            Ok(parsed) => options.log = Some(parsed),
            Err(e) => return Ok(Err(format!("log message: {}\n{}", e.reason, e.pointed()))),
        }
    }
    Ok(Ok(options))
}

/// Replaces the points of `kind` with those `wanted`, answering each.
fn replace(points: &mut Points, d: &mut Debugger, kind: &Kind, wanted: Vec<Wanted>) -> Value {
    points.clear(d, kind);
    let answers: Vec<Value> = wanted
        .into_iter()
        .map(|wanted| match wanted {
            Ok((what, address)) => {
                let id = points.add(d, kind.clone(), what);
                let mut answer = json!({"verified": true, "id": id});
                if let Some(address) = address {
                    answer["instructionReference"] = json!(format!("0x{address:04X}"));
                }
                answer
            }
            Err(message) => json!({"verified": false, "message": message}),
        })
        .collect();
    json!({ "breakpoints": answers })
}

/// A breakpoint at `point` with the options `a` gives (`log`: log points
/// taken).
fn wanted_at(
    d: &Debugger,
    a: &Arguments<'_>,
    point: Breakpoint,
    log: bool,
) -> Result<Wanted, String> {
    let address = match point {
        Breakpoint::At(address) => Some(address),
        _ => None,
    };
    Ok(options(d, a, log)?.map(|options| (What::Break(point, options), address)))
}

/// `setBreakpoints`: a source's lines, each with its condition, hit count
/// or log message.
pub(crate) fn set_source(
    points: &mut Points,
    d: &mut Debugger,
    args: &Arguments<'_>,
) -> Result<Value, String> {
    let source = match args.map.get("source") {
        Some(Value::Object(source)) => source.clone(),
        _ => return Err("setBreakpoints needs `source`, an object with a `path`".into()),
    };
    let path = source
        .get("path")
        .and_then(Value::as_str)
        .unwrap_or_default()
        .to_owned();
    let mut lines = Vec::new();
    let mut wanted = Vec::new();
    // Checked before the old set goes: a refused request changes nothing.
    for breakpoint in args.objects("breakpoints")? {
        let line = breakpoint
            .get("line")
            .and_then(Value::as_i64)
            .ok_or("setBreakpoints: each of `breakpoints` is an object with a `line`, a number")?;
        lines.push(line);
        let address = u32::try_from(line)
            .ok()
            .and_then(|line| d.address_of_line(&path, line));
        wanted.push(match address {
            Some(address) => wanted_at(d, &args.of(breakpoint), Breakpoint::At(address), true)?,
            None => Err(format!("no code came from line {line}")),
        });
    }
    let mut body = replace(points, d, &Kind::Source(path), wanted);
    if let Some(answers) = body["breakpoints"].as_array_mut() {
        for (answer, line) in answers.iter_mut().zip(lines) {
            answer["line"] = json!(line);
            answer["source"] = Value::Object(source.clone());
        }
    }
    Ok(body)
}

/// `setFunctionBreakpoints`: each `name` a place as the monitor's `break`
/// takes it (a label or any address expression, `FILE:LINE`, a robot
/// command `/3A`, `unknown`).
pub(crate) fn set_functions(
    points: &mut Points,
    d: &mut Debugger,
    args: &Arguments<'_>,
) -> Result<Value, String> {
    let mut wanted = Vec::new();
    for breakpoint in args.objects("breakpoints")? {
        let a = args.of(breakpoint);
        let name = a
            .string("name")?
            .ok_or("setFunctionBreakpoints: each of `breakpoints` has a `name`, a string")?;
        wanted.push(match breaks::place(d, name.trim()) {
            Ok(point) => wanted_at(d, &a, point, false)?,
            Err(failure) => Err(failure.message()),
        });
    }
    Ok(replace(points, d, &Kind::Function, wanted))
}

/// `setInstructionBreakpoints`: each at `instructionReference` + `offset`
/// bytes.
pub(crate) fn set_instructions(
    points: &mut Points,
    d: &mut Debugger,
    args: &Arguments<'_>,
) -> Result<Value, String> {
    let mut wanted = Vec::new();
    for breakpoint in args.objects("breakpoints")? {
        let a = args.of(breakpoint);
        let reference = a.string("instructionReference")?.ok_or(
            "setInstructionBreakpoints: each of `breakpoints` has an `instructionReference`, a string",
        )?;
        let offset = a.integer("offset")?.unwrap_or(0);
        wanted.push(match super::memory::address(d, reference, offset) {
            Ok(address) => wanted_at(d, &a, Breakpoint::At(address), false)?,
            Err(why) => Err(why),
        });
    }
    Ok(replace(points, d, &Kind::Instruction, wanted))
}

/// `$9000` or `$9000-$9002`, as a `dataId`.
fn data_id(start: u16, end: u16) -> String {
    if start == end {
        format!("0x{start:04X}")
    } else {
        format!("0x{start:04X}..0x{end:04X}")
    }
}

/// The range a `dataId` (or a name typed as the monitor's `watch` takes
/// it: `ADDR` or `ADDR..ADDR`) covers.
fn range(d: &Debugger, text: &str) -> Result<(u16, u16), String> {
    let address = |part: &str| super::memory::address(d, part.trim(), 0);
    let (start, end) = match text.split_once("..") {
        Some((a, b)) => (address(a)?, address(b)?),
        None => {
            let a = address(text)?;
            (a, a)
        }
    };
    if end < start {
        return Err(format!("`{text}`: the range's end is below its start"));
    }
    Ok((start, end))
}

/// `dataBreakpointInfo`: memory can be watched (a name is an address
/// expression or a range, `bytes` long from it with `asAddress`);
/// registers and flags cannot.
pub(crate) fn data_info(
    d: &Debugger,
    args: &Arguments<'_>,
    registers: bool,
) -> Result<Value, String> {
    let name = args
        .string("name")?
        .ok_or("dataBreakpointInfo needs `name`, a string")?;
    let bytes = args.integer("bytes")?;
    let no = |why: String| json!({"dataId": Value::Null, "description": why});
    if registers {
        return Ok(no(format!(
            "{name} is a register or a flag: only memory can be watched"
        )));
    }
    let (start, mut end) = match range(d, name) {
        Ok(range) => range,
        Err(why) => return Ok(no(why)),
    };
    if let Some(bytes) = bytes {
        if !(1..=0x1_0000).contains(&bytes) {
            return Ok(no(format!("`bytes` is 1 to 65536, not {bytes}")));
        }
        let last = i64::from(start) + bytes - 1;
        // Past $FFFF is said, not cut short without a word: the watch
        // would cover fewer bytes than the client asked for.
        let Ok(last) = u16::try_from(last) else {
            return Ok(no(format!(
                "{bytes} bytes from ${start:04X} run past $FFFF: at most {} fit",
                0x1_0000 - i64::from(start)
            )));
        };
        end = last;
    }
    let place = d
        .symbols()
        .place(start)
        .map(|p| format!(" ({p})"))
        .unwrap_or_default();
    let shown = if start == end {
        format!("${start:04X}{place}")
    } else {
        format!("${start:04X}-${end:04X}{place}")
    };
    Ok(json!({
        "dataId": data_id(start, end),
        "description": shown,
        "accessTypes": ["read", "write", "readWrite"],
        "canPersist": true,
    }))
}

/// `setDataBreakpoints`: watchpoints, each on a `dataId`'s range for its
/// `accessType` (the monitor's `watch`: reads and writes unless told).
pub(crate) fn set_data(
    points: &mut Points,
    d: &mut Debugger,
    args: &Arguments<'_>,
) -> Result<Value, String> {
    let mut wanted = Vec::new();
    for breakpoint in args.objects("breakpoints")? {
        let a = args.of(breakpoint);
        let id = a
            .string("dataId")?
            .ok_or("setDataBreakpoints: each of `breakpoints` has a `dataId`, a string")?;
        let kind = match a.string("accessType")? {
            None | Some("readWrite") => WatchKind::Access,
            Some("read") => WatchKind::Read,
            Some("write") => WatchKind::Write,
            Some(other) => {
                return Err(format!(
                    "setDataBreakpoints: `accessType` is read, write or readWrite, not `{other}`"
                ));
            }
        };
        let conditional = [a.string("condition")?, a.string("hitCondition")?]
            .iter()
            .any(|t| t.is_some_and(|t| !t.trim().is_empty()));
        wanted.push(if conditional {
            Err(
                "a data breakpoint stops at every access: it takes no condition or hit count"
                    .into(),
            )
        } else {
            range(d, id).map(|(start, end)| (What::Watch(Watch { start, end, kind }), None))
        });
    }
    Ok(replace(points, d, &Kind::Data, wanted))
}

/// The stop's description for watchpoint hits: `wrote $05 to $0200 by
/// $0412 (loop+$2)`.
pub(crate) fn watch_text(d: &Debugger, access: &crate::hooks::Access, pc: u16) -> String {
    let place = d
        .symbols()
        .place(pc)
        .map(|p| format!(" ({p})"))
        .unwrap_or_default();
    format!(
        "{} ${:02X} {} ${:04X} by ${pc:04X}{place}",
        if access.write { "wrote" } else { "read" },
        access.value,
        if access.write { "to" } else { "from" },
        access.address,
    )
}
