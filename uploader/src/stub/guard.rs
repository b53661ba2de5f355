//! What a person at a stop may change on the robot: memory the program
//! owns, and registers the ROM can go on with. The virtual monitor knows
//! every byte of its board; on the robot the host knows the board's RAM,
//! the image it uploaded, the stub and the ROM's hooks and table, and
//! refuses the rest before anything goes on the line (fresh10 F16, F17;
//! hostile11 F1).

use std::ops::RangeInclusive;

use romlib::installed::{TABLE, TABLE_LEN};

use super::link::StubPlan;
use crate::image::{RomProfile, UploadImage};

/// The decimal flag in P.
const DECIMAL: u8 = 0x08;

/// The robot's memory as the host knows it, for the writes and the
/// registers a person asks for.
#[derive(Debug, Clone)]
pub struct Guard {
    /// `HOOK_UNKNOWN`'s and `HOOK_LOOP`'s `JMP`s.
    hooks: [RangeInclusive<u16>; 2],
    /// The ROM's table of installed extensions.
    table: RangeInclusive<u16>,
    /// The ROM's entries that do not return (`CMD_DONE`, and the hooks'
    /// own targets, `BAD_COMMAND` and the control loop): the only places
    /// in the ROM a PC is set to. A subroutine's `RTS` would return on the
    /// handler's stack, where nothing called it (hostile11 F5).
    ends: Vec<u16>,
    /// The RAM the ROM leaves to extensions: its user zero page and user
    /// RAM.
    user: Vec<RangeInclusive<u16>>,
}

impl Guard {
    /// The guard of a robot with `profile`'s ROM.
    #[must_use]
    pub fn new(profile: &RomProfile) -> Guard {
        let jmp = |at: u16| at..=at.wrapping_add(2);
        Guard {
            hooks: [jmp(profile.hook_unknown), jmp(profile.hook_loop)],
            table: TABLE..=TABLE + (TABLE_LEN as u16 - 1),
            ends: profile
                .loader_services
                .as_ref()
                .map(|services| services.cmd_done)
                .into_iter()
                .chain(
                    profile
                        .reset_targets
                        .into_iter()
                        .flat_map(|(unknown, main)| [unknown, main]),
                )
                .collect(),
            user: profile
                .user_zero_page
                .iter()
                .map(|zp| u16::from(*zp.start())..=u16::from(*zp.end()))
                .chain(std::iter::once(profile.user_ram.clone()))
                .collect(),
        }
    }

    /// Why a write at `at` by a person is refused, if it is: only RAM the
    /// program owns is written (the ROM's user zero page and user RAM, and
    /// the image's own memory), not the hooks, the table or the image's
    /// chain slots (an upload sets those, each verified before it is
    /// reached), nor the ROM's own RAM (its receive ring, its stack), the
    /// ROM, the I/O page or the KIM bus beyond the image (a card's
    /// registers may sit there, and a write may start its hardware).
    #[must_use]
    pub fn refuse_write(&self, at: u16, image: &UploadImage) -> Option<String> {
        if let Some(hook) = self.hooks.iter().position(|hook| hook.contains(&at)) {
            let name = ["HOOK_UNKNOWN", "HOOK_LOOP"][hook];
            return Some(format!(
                "${at:04X} is in {name}'s JMP, which the session needs to take its breakpoints out and give the hook back; an upload changes the hooks, each verified before it is reached"
            ));
        }
        if self.table.contains(&at) {
            return Some(format!(
                "${at:04X} is in the ROM's table of installed extensions (${:04X}-${:04X}), which uploads, undo and `installed` read: an upload changes it, verified",
                self.table.start(),
                self.table.end()
            ));
        }
        if let Some(hook) = image.hooks().iter().find(|hook| {
            hook.chain
                .is_some_and(|slot| at == slot || at == slot.wrapping_add(1))
        }) {
            return Some(format!(
                "${at:04X} is in the chain slot of the image's {} handler (${:04X}), which the upload set to where the hook went before it, verified: written by hand, it sends every command the image does not take anywhere",
                hook.kind.rom_symbol(),
                hook.handler
            ));
        }
        if image.contains(at) || self.user.iter().any(|range| range.contains(&at)) {
            return None;
        }
        let users: Vec<String> = self
            .user
            .iter()
            .map(|range| format!("${:04X}-${:04X}", range.start(), range.end()))
            .collect();
        Some(format!(
            "${at:04X} is {}: the robot's monitor writes the RAM the ROM leaves to extensions ({}) and the image's own memory only",
            region(at),
            users.join(", ")
        ))
    }

    /// Why a read at `at` by a person is refused, if it is: a read of the
    /// I/O page, or of the KIM bus outside the image, is a real bus read
    /// on the robot, and a register there may change when read (fresh15
    /// F7: reading the ADC card's result at a stop cleared its status, and
    /// the handler then said "no card"). The virtual robot shows such
    /// memory without reading it; the robot cannot.
    #[must_use]
    pub fn refuse_read(&self, at: u16, image: &UploadImage) -> Option<String> {
        use platform::map::{IO_END, IO_START, KIM_BUS};
        let device = (IO_START..=IO_END).contains(&at) || KIM_BUS.contains(&at);
        (device && !image.contains(at)).then(|| {
            format!(
                "${at:04X} is {}, and reading a register there can change it (a status cleared, a result taken): the program would then read something else; the robot's monitor reads RAM, the ROM and the image's own memory only",
                region(at)
            )
        })
    }

    /// Why the registers `new` are refused where the robot is stopped
    /// with `old`, if they are: a PC that is no instruction the host knows
    /// (inside the stub, inside an instruction of the image, in the ROM
    /// but not at an entry that ends a handler, or in memory that is not
    /// the image's or the ROM's), or the decimal flag set (the ROM turns
    /// bytes into hex digits with `ADC`, so every answer of a robot going
    /// on in decimal mode is wrong).
    #[must_use]
    pub fn refuse_registers(
        &self,
        old: &super::Registers,
        new: &super::Registers,
        image: &UploadImage,
        starts: Option<&[u16]>,
        stub: &StubPlan,
    ) -> Option<String> {
        if new.p & DECIMAL != 0 && old.p & DECIMAL == 0 {
            return Some(
                "the decimal flag (D) set: the ROM makes its answers' hex digits with ADC, so in decimal mode every answer (each `/7R` read included) would come back wrong until a reset".into(),
            );
        }
        let pc = new.pc;
        if pc == old.pc {
            return None;
        }
        if stub.contains(pc) {
            return Some(format!(
                "PC=${pc:04X} is in the debug stub (${:04X}-${:04X}): the robot would run the stub's code as the program's",
                stub.address,
                u32::from(stub.address) + stub.bytes.len() as u32 - 1
            ));
        }
        if image.contains(pc) {
            // hostile12 F1: a label counts as an instruction's start, and
            // the chain slot's has one (the operand of `JMP PREV`).
            let slot = image.hooks().iter().any(|hook| {
                hook.chain
                    .is_some_and(|slot| pc == slot || pc == slot.wrapping_add(1))
            });
            if slot || !image.is_code(pc) {
                return Some(format!(
                    "${pc:04X} is {} of the image, not one of its instructions: the robot would run the middle of one, or data",
                    if slot {
                        "in a chain slot (a JMP's operand)"
                    } else {
                        "data"
                    }
                ));
            }
            if starts.is_some_and(|starts| starts.binary_search(&pc).is_err()) {
                return Some(format!(
                    "no instruction of the image starts at ${pc:04X} (its line tables start a line at every instruction): the robot would run the middle of one"
                ));
            }
            return None;
        }
        if pc >= platform::map::ROM_START {
            // fresh11 F9: `set PC $F000` ran the reset code with the stub
            // hooked; hostile11 F5: a subroutine's RTS jammed the CPU.
            if self.ends.contains(&pc) {
                return None;
            }
            let ends: Vec<String> = self.ends.iter().map(|at| format!("${at:04X}")).collect();
            return Some(format!(
                "PC=${pc:04X} is in the ROM but not one of the entries that end a handler ({}: `CMD_DONE`, and the unknown command's and the control loop's own): anywhere else the robot runs the middle of the ROM, or a subroutine whose RTS returns where nothing called it",
                ends.join(", ")
            ));
        }
        Some(format!(
            "PC=${pc:04X} is {}, where the image has no code: the robot would run whatever is there; set PC to an instruction of the image, or `CMD_DONE` to end the command",
            region(pc)
        ))
    }
}

/// Whether `at` is RAM the program owns: the board's RAM, or the image's.
#[must_use]
pub fn ram(at: u16, image: &UploadImage) -> bool {
    at <= platform::map::RAM_END || image.contains(at)
}

/// What the board has at `at`, for a refusal.
fn region(at: u16) -> &'static str {
    use platform::map::{IO_END, IO_START, KIM_BUS, ROM_START};
    if at >= ROM_START {
        "the ROM"
    } else if (IO_START..=IO_END).contains(&at) {
        "in the I/O page (the 6522's and the ACIA's registers, the drive and sense latches)"
    } else if KIM_BUS.contains(&at) {
        "on the KIM bus outside the image (a card's registers may sit there)"
    } else if at <= platform::map::RAM_END {
        "the ROM's own RAM (its variables, the stack, the receive ring, the command buffer)"
    } else {
        "memory the board does not have"
    }
}
