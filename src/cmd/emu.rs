//! `scorpion emu`: run 6502 code on the emulator.
//!
//! `scorpion emu run` loads a raw image into the plain 64 KiB RAM machine
//! and runs it until a trap, a JAM or a cycle limit, then reports the CPU
//! state (or one JSON object for scripts).

use std::io::{BufWriter, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use emulator::{Hooks, NoHooks, RamMachine, Stop, StopAtTrap, Tracer};
use miette::{Context, IntoDiagnostic};

use crate::args;

/// Run 6502 code on the emulator.
#[derive(Debug, clap::Args)]
pub(crate) struct Args {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, clap::Subcommand)]
enum Command {
    /// Run a raw binary on the plain 64 KiB RAM machine (no I/O).
    ///
    /// The machine starts with RAM cleared and the image loaded, goes
    /// through the 6502's 7-cycle reset sequence (counted in the cycles),
    /// then runs from --start or from the reset vector at $FFFC. It stops at
    /// a JAM opcode, at the cycle limit, or with --until-trap at the first
    /// instruction that jumps or branches to itself (`JMP *`, `BNE *`), the
    /// way test programs end.
    ///
    /// Exit status: 0 when the run ended as asked (a trap with --until-trap,
    /// the cycle limit without it), 1 on a JAM or an error, 3 when
    /// --until-trap was given but the cycle limit came first.
    #[command(verbatim_doc_comment)]
    Run(RunArgs),
}

/// The default cycle limit: a few seconds of wall time, 17 minutes of a
/// 1 MHz Scorpion's.
const MAX_CYCLES: u64 = 1_000_000_000;
/// The default with --trace, which writes about 80 bytes per instruction.
const MAX_CYCLES_TRACED: u64 = 1_000_000;

#[derive(Debug, clap::Args)]
pub(crate) struct RunArgs {
    /// The raw binary to run.
    image: PathBuf,
    /// Address of the image's first byte.
    #[arg(long, value_parser = args::address, default_value = "0", value_name = "ADDR")]
    load: u16,
    /// Where to start (default: the reset vector at $FFFC).
    #[arg(long, value_parser = args::address, value_name = "ADDR")]
    start: Option<u16>,
    /// Stop at the first instruction that jumps or branches to itself.
    #[arg(long)]
    until_trap: bool,
    /// Stop after this many cycles (checked between instructions) [default:
    /// 1000000000, or 1000000 with --trace]. Keeps a runaway program from
    /// hanging the command.
    #[arg(long, value_parser = cycles, value_name = "N")]
    max_cycles: Option<u64>,
    /// Write one line per instruction to FILE: address, bytes, disassembly,
    /// registers before it, and the cycle it starts at.
    #[arg(long, value_name = "FILE")]
    trace: Option<PathBuf>,
    /// Print one JSON object: stop, pc, a, x, y, sp, p, instructions, cycles,
    /// seconds.
    #[arg(long)]
    json: bool,
}

/// A cycle count: decimal, `_` allowed as a separator (`50_000_000`).
fn cycles(text: &str) -> Result<u64, String> {
    text.replace('_', "")
        .parse()
        .map_err(|_| format!("`{text}` is not a cycle count (write a whole number like 50000000)"))
}

pub(crate) fn run(args: &Args) -> miette::Result<ExitCode> {
    match &args.command {
        Command::Run(run) => run_image(run),
    }
}

fn run_image(args: &RunArgs) -> miette::Result<ExitCode> {
    let image = hostfs::read(&args.image, hostfs::RAW_IMAGE)
        .wrap_err_with(|| format!("cannot read {}", args.image.display()))?;
    // fresh11 F11: an ELF's header ran as code.
    if image.starts_with(b"\x7fELF") {
        miette::bail!(
            help = "`scorpion debug --image FILE` runs a linked image on the virtual Scorpion; `scorpion link --format bin` makes raw bytes for `emu run`",
            "{} is an ELF file: `emu run` runs raw 6502 bytes, and would run its header as code",
            args.image.display()
        );
    }
    let mut machine = RamMachine::with_image(args.load, &image)
        .wrap_err_with(|| format!("cannot load {}", args.image.display()))?;
    machine.reset();
    if let Some(start) = args.start {
        machine.cpu.pc = start;
    }
    let limit = args.max_cycles.unwrap_or(if args.trace.is_some() {
        MAX_CYCLES_TRACED
    } else {
        MAX_CYCLES
    });
    let until = machine.cpu.cycles().saturating_add(limit);

    let started = Instant::now();
    let stop = match &args.trace {
        None if args.until_trap => machine.run_with(until, &mut StopAtTrap),
        None => machine.run_with(until, &mut NoHooks),
        Some(path) => {
            let file = std::fs::File::create(path)
                .into_diagnostic()
                .wrap_err_with(|| format!("cannot create the trace file {}", path.display()))?;
            let mut tracer = Tracer::new(BufWriter::new(file));
            let stop = if args.until_trap {
                run_traced(&mut machine, until, (StopAtTrap, &mut tracer))
            } else {
                run_traced(&mut machine, until, &mut tracer)
            };
            tracer
                .finish()
                .into_diagnostic()
                .wrap_err_with(|| format!("cannot write the trace file {}", path.display()))?;
            stop
        }
    };
    let seconds = started.elapsed().as_secs_f64();
    report(args, &machine, stop, seconds)?;
    Ok(match stop {
        Stop::Jam { .. } => ExitCode::FAILURE,
        Stop::Limit if args.until_trap => ExitCode::from(3),
        _ => ExitCode::SUCCESS,
    })
}

fn run_traced<H: Hooks>(machine: &mut RamMachine, until: u64, mut hooks: H) -> Stop {
    machine.run_with(until, &mut hooks)
}

/// The instruction at `pc`, disassembled from the machine's memory.
fn instruction_at(machine: &RamMachine, pc: u16) -> String {
    isa::Instruction::decode_with(pc, |address| machine.bus.bytes()[usize::from(address)])
        .to_string()
}

fn report(args: &RunArgs, machine: &RamMachine, stop: Stop, seconds: f64) -> miette::Result<()> {
    let cpu = &machine.cpu;
    let mut out = std::io::stdout().lock();
    if args.json {
        let stop_name = match stop {
            Stop::Trap { .. } => "trap",
            Stop::Jam { .. } => "jam",
            // Hooks here never stop the run by themselves, nor does RAM.
            Stop::Limit | Stop::Hook { .. } | Stop::Bus => "cycle_limit",
        };
        // Written by hand to keep the keys in the documented order; every
        // value but `stop` is a JSON number.
        let object = format!(
            "{{\"stop\":\"{stop_name}\",\"pc\":{},\"a\":{},\"x\":{},\"y\":{},\"sp\":{},\"p\":{},\"instructions\":{},\"cycles\":{},\"seconds\":{}}}",
            cpu.pc,
            cpu.a,
            cpu.x,
            cpu.y,
            cpu.s,
            cpu.p(),
            cpu.instructions(),
            cpu.cycles(),
            serde_json::Number::from_f64(seconds).unwrap_or_else(|| 0.into()),
        );
        writeln!(out, "{object}").into_diagnostic()?;
        return Ok(());
    }
    let reason = match stop {
        Stop::Trap { pc } => format!("trap at ${pc:04X} ({})", instruction_at(machine, pc)),
        Stop::Jam { pc, opcode } => {
            format!("JAM: opcode ${opcode:02X} at ${pc:04X} halted the processor")
        }
        Stop::Limit | Stop::Hook { .. } | Stop::Bus => {
            let limit = args.max_cycles.unwrap_or(if args.trace.is_some() {
                MAX_CYCLES_TRACED
            } else {
                MAX_CYCLES
            });
            format!("cycle limit ({limit} cycles; raise it with --max-cycles)")
        }
    };
    let mhz = if seconds > 0.0 {
        cpu.cycles() as f64 / seconds / 1e6
    } else {
        0.0
    };
    writeln!(out, "stop: {reason}").into_diagnostic()?;
    writeln!(
        out,
        "registers: PC=${:04X} A=${:02X} X=${:02X} Y=${:02X} SP=${:02X} P=${:02X} ({})",
        cpu.pc,
        cpu.a,
        cpu.x,
        cpu.y,
        cpu.s,
        cpu.p(),
        emulator::cpu::flags_text(cpu.p())
    )
    .into_diagnostic()?;
    writeln!(out, "instructions: {}", cpu.instructions()).into_diagnostic()?;
    writeln!(out, "cycles: {}", cpu.cycles()).into_diagnostic()?;
    writeln!(out, "seconds: {seconds:.6}").into_diagnostic()?;
    writeln!(out, "emulated MHz: {mhz:.1}").into_diagnostic()?;
    Ok(())
}
