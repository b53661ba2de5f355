//! The exception breakpoints an assembly program on the Scorpion meets:
//! a JAM (KIL) opcode, which halts the 6502; a BRK, which the ROM's
//! interrupt handler passes over; and a card's or the surroundings'
//! script failing, which stops the robot. A JAM and a fault end the run
//! whatever the filters say (the robot cannot go on): with their filter on
//! the session stops there as at an exception, with it off the program
//! ends. A BRK is a breakpoint of the debugger's own, at the handler the
//! BRK vector points to, with the condition that the flags it pushed have
//! B set (an IRQ's have it clear): the monitor's expression language.

use serde_json::{Value, json};

use super::points::What;
use crate::{Breakpoint, Debugger, Expr, PointOptions};

/// A filter: its name, its label, what it catches, on unless the client
/// says.
struct Filter {
    name: &'static str,
    label: &'static str,
    description: &'static str,
    default: bool,
}

/// The filters, as `initialize` lists them.
const FILTERS: [Filter; 3] = [
    Filter {
        name: "jam",
        label: "JAM (KIL) opcode",
        description: "the 6502 halts on a JAM opcode: a jump into data or a bad address",
        default: true,
    },
    Filter {
        name: "brk",
        label: "BRK",
        description: "a BRK instruction (the ROM's interrupt handler passes over it)",
        default: false,
    },
    Filter {
        name: "card",
        label: "A card's or the surroundings' fault",
        description: "a card's or the surroundings' script failed: the robot stops",
        default: true,
    },
];

/// The 6502's IRQ/BRK vector.
const BRK_VECTOR: u16 = 0xFFFE;

/// `exceptionBreakpointFilters` of the capabilities.
pub(crate) fn capabilities() -> Value {
    FILTERS
        .iter()
        .map(|f| {
            json!({"filter": f.name, "label": f.label, "description": f.description,
                   "default": f.default})
        })
        .collect()
}

/// The filters on before the client says.
pub(crate) fn defaults() -> Vec<&'static str> {
    FILTERS
        .iter()
        .filter(|f| f.default)
        .map(|f| f.name)
        .collect()
}

/// The filter named `name`.
pub(crate) fn named(name: &str) -> Option<&'static str> {
    FILTERS.iter().find(|f| f.name == name).map(|f| f.name)
}

/// The breakpoint that stops at a BRK: at the handler the vector points
/// to, when the flags pushed have B set.
///
/// # Errors
/// The condition does not read (a bug: it is fixed text).
pub(crate) fn brk_point(d: &Debugger) -> Result<What, String> {
    let bus = &d.robot().robot().bus;
    let handler = u16::from_le_bytes([
        emulator::Bus::peek(bus, BRK_VECTOR),
        emulator::Bus::peek(bus, BRK_VECTOR.wrapping_add(1)),
    ]);
    // After the sequence S is 3 below what it was: P at $0101+S.
    let condition = Expr::parse("([$101 + S] & $10) != 0", d.symbols())
        .map_err(|e| format!("the BRK condition: {}", e.reason))?;
    Ok(What::Break(
        Breakpoint::At(handler),
        PointOptions {
            condition: Some(condition),
            ..PointOptions::default()
        },
    ))
}

/// What the session stopped at, for `exceptionInfo`.
#[derive(Debug, Clone)]
pub(crate) struct Exception {
    /// The filter that caught it (or `error`, a failure no filter names).
    pub(crate) id: &'static str,
    /// One line.
    pub(crate) description: String,
    /// In full (a script's place and snippet).
    pub(crate) details: String,
}

impl Exception {
    /// The BRK the robot is stopped after, at its handler.
    pub(crate) fn brk(d: &Debugger) -> Exception {
        let bus = &d.robot().robot().bus;
        let s = u16::from(d.cpu().s);
        let pushed = u16::from_le_bytes([
            emulator::Bus::peek(bus, 0x0102 + s),
            emulator::Bus::peek(bus, 0x0103 + s),
        ]);
        // BRK pushes its address + 2 (it skips a padding byte).
        let at = pushed.wrapping_sub(2);
        let place = d
            .symbols()
            .place(at)
            .map(|p| format!(" ({p})"))
            .unwrap_or_default();
        Exception {
            id: "brk",
            description: format!("BRK at ${at:04X}{place}"),
            details: format!(
                "a BRK at ${at:04X}{place}; the robot is at its handler, ${:04X}",
                d.cpu().pc
            ),
        }
    }

    /// The failure a run ended with.
    pub(crate) fn from_error(error: &crate::Error) -> Exception {
        let id = match error {
            crate::Error::Robot(romlib::Error::Jam { .. }) => "jam",
            crate::Error::Robot(
                romlib::Error::Card { .. } | romlib::Error::Surroundings { .. },
            ) => "card",
            _ => "error",
        };
        // A script's failure says what went wrong in its own message.
        let description = match error {
            crate::Error::Robot(
                romlib::Error::Card { message, .. } | romlib::Error::Surroundings { message, .. },
            ) => format!("{error}: {message}"),
            _ => error.to_string(),
        };
        let help = miette::Diagnostic::help(error)
            .map(|help| format!(" ({help})"))
            .unwrap_or_default();
        Exception {
            id,
            details: format!("{description}{help}"),
            description,
        }
    }

    /// `exceptionInfo`'s body.
    pub(crate) fn info(&self) -> Value {
        json!({
            "exceptionId": self.id,
            "description": self.description,
            "breakMode": "always",
            "details": {"message": self.details},
        })
    }
}
