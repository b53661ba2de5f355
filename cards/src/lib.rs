//! Peripheral cards on the KIM bus and the robot's surroundings, as
//! scripts the virtual Scorpion runs: a card owner rehearses an extension
//! against the card before it goes near the robot, without writing Rust.
//!
//! - [`ScriptCard`]: a card whose registers a Rhai script serves (an
//!   emulator [`Device`](emulator::board::Device), mapped with
//!   `VirtualScorpion::map_card`). See `docs/CARDS.md` for the script's
//!   interface.
//! - [`ScriptWorld`]: surroundings that change the robot's inputs over
//!   robot time (a [`romlib::Surroundings`]).
//! - [`Room`]: the robot in a room from a world file (`world.toml`:
//!   walls, obstacles, floor lines, the robot's pose, drive and sensors;
//!   docs/WORLD.md), its pose following the drive motors' steps, a world
//!   script adding to it.
//! - [`CardArg`]: the `--card FILE[@ADDR]` argument.
//!
//! Scripts are untrusted input: they reach no file, network or process
//! and see no clock but robot time; each call into one has an operation
//! budget ([`OPERATION_BUDGET`]) and a script earns
//! [`OPERATIONS_PER_MICROSECOND`] of robot time, each call paying
//! [`CALL_COST`] for itself; wake-ups move forward;
//! what it prints is bounded ([`Printed`]); every failure is a
//! [`ScriptError`] located in the script. Cards in Rust
//! implement the same `Device` trait (`examples/adc_in_rust.rs`).

mod card;
mod clock;
mod error;
mod printed;
pub mod room;
mod sandbox;
mod script;
mod world;

pub use card::ScriptCard;
pub use clock::{CALL_COST, OPERATIONS_PER_MICROSECOND};
pub use error::{Located, ScriptError, WorldMistake};
pub use printed::{MAX_PRINTED_BYTES, MAX_PRINTED_LINES, Printed};
pub use room::{Room, RoomView};
pub use sandbox::{MAX_FUNCTIONS, MAX_VARIABLES, OPERATION_BUDGET};
pub use world::ScriptWorld;

/// `--card FILE[@ADDR]`: a card script and where to put it (hex, `$` or
/// `0x` allowed), if not at the script's own `BASE`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CardArg {
    /// The script's path.
    pub path: std::path::PathBuf,
    /// The base address, if given.
    pub base: Option<u16>,
}

impl std::str::FromStr for CardArg {
    type Err = String;

    fn from_str(text: &str) -> Result<CardArg, String> {
        let (path, base) = match text.rsplit_once('@') {
            Some((path, address)) => {
                let digits = address
                    .trim_start_matches('$')
                    .trim_start_matches("0x")
                    .trim_start_matches("0X");
                let base = u16::from_str_radix(digits, 16).map_err(|_| {
                    format!("`{address}` is not an address (write FILE@9000 or FILE@$9000)")
                })?;
                (path, Some(base))
            }
            None => (text, None),
        };
        if path.is_empty() {
            return Err("no script file before `@`".into());
        }
        Ok(CardArg {
            path: path.into(),
            base,
        })
    }
}
#[cfg(test)]
mod tests;
