//! One module per subcommand.

pub(crate) mod ask;
pub(crate) mod asm;
pub(crate) mod backup;
pub(crate) mod build;
pub(crate) mod config;
pub(crate) mod dap;
pub(crate) mod debug;
pub(crate) mod disasm;
pub(crate) mod emu;
pub(crate) mod host_line;
pub(crate) mod installed;
pub(crate) mod link;
pub(crate) mod new;
pub(crate) mod ports;
pub(crate) mod profile;
pub(crate) mod read;
pub(crate) mod rig;
pub(crate) mod rom;
pub(crate) mod sim;
pub(crate) mod test;
pub(crate) mod upload;
pub(crate) mod view;
