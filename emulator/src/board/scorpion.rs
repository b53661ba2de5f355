//! The Scorpion controller card as a [`Bus`]: RAM, the KIM-bus expansion
//! space, the I/O page with the 6522, the 6551 and the board latches, and the
//! write-protected ROM; and [`Scorpion`], the card with its CPU and the host
//! side of everything (the serial line, the bumpers, the sensors, the
//! motors).
//!
//! RAM and ROM reads take a direct path through a 256-entry page table;
//! only the I/O page and pages holding a KIM-bus device call out. Timed
//! devices are never ticked: the board keeps the earliest cycle at which any
//! of them will raise its interrupt output by itself, and [`Bus::poll`]
//! compares the CPU's cycle with it once per instruction, so the CPU runs
//! freely between device events.

use super::acia::{self, Acia, HostByte};
use super::device::Device;
use super::motor::Stepper;
use super::scene::Scene;
use super::serial::{Baud, CPU_HZ, FrameFormat};
use super::via::{self, Via};
use crate::bus::{Bus, Interrupts, Line};
use crate::machine::Machine;
use platform::map::{self, drive, port_b};

/// What a page of the address space is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Page {
    /// Read and written directly (RAM, KIM-bus RAM).
    Ram,
    /// Read directly, writes ignored.
    Rom,
    /// The I/O page.
    Io,
    /// Holds (part of) a KIM-bus device; the rest of the page is RAM.
    Kim,
    /// Nothing answers.
    Open,
}

/// A device a test or an example plugged into the KIM-bus expansion space.
#[derive(Debug)]
struct KimSlot {
    start: u16,
    end: u16,
    device: Box<dyn Device>,
    line: Line,
}

/// A handle to a KIM-bus device, returned when it is mapped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct KimSlotId(usize);

/// The four stepper motors of the robot.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Motor {
    /// The left drive wheel.
    Left,
    /// The right drive wheel.
    Right,
    /// The horizontal scanner.
    HorizontalScanner,
    /// The vertical scanner.
    VerticalScanner,
}

impl Motor {
    const ALL: [Motor; 4] = [
        Motor::Left,
        Motor::Right,
        Motor::HorizontalScanner,
        Motor::VerticalScanner,
    ];

    fn index(self) -> usize {
        match self {
            Motor::Left => 0,
            Motor::Right => 1,
            Motor::HorizontalScanner => 2,
            Motor::VerticalScanner => 3,
        }
    }

    /// Its step line, direction line (port B) and driver enable (`DRIVE`).
    fn wiring(self) -> (u8, u8, u8) {
        match self {
            Motor::Left => (port_b::LEFT_STEP, port_b::LEFT_DIR, drive::LEFT_MOTOR),
            Motor::Right => (port_b::RIGHT_STEP, port_b::RIGHT_DIR, drive::RIGHT_MOTOR),
            Motor::HorizontalScanner => (port_b::H_STEP, port_b::SCAN_DIR, drive::H_SCANNER),
            Motor::VerticalScanner => (port_b::V_STEP, port_b::SCAN_DIR, drive::V_SCANNER),
        }
    }
}

/// The 64 KiB behind the address space, held in the board itself rather
/// than behind a pointer: the run loop then reaches a byte with one load
/// from the board's address, which it keeps in a register (a pointer field
/// would be reloaded after every call the loop might make).
#[derive(Clone)]
struct Memory([u8; 0x1_0000]);

impl core::fmt::Debug for Memory {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        // 64 KiB of bytes helps nobody; the vectors identify the ROM.
        let word = |at: usize| u16::from_le_bytes([self.0[at], self.0[at + 1]]);
        f.debug_struct("Memory")
            .field(
                "reset_vector",
                &format_args!("${:04X}", word(usize::from(crate::cpu::RESET_VECTOR))),
            )
            .field(
                "irq_vector",
                &format_args!("${:04X}", word(usize::from(crate::cpu::IRQ_VECTOR))),
            )
            .finish_non_exhaustive()
    }
}

impl core::ops::Deref for Memory {
    type Target = [u8; 0x1_0000];
    fn deref(&self) -> &[u8; 0x1_0000] {
        &self.0
    }
}

impl core::ops::DerefMut for Memory {
    fn deref_mut(&mut self) -> &mut [u8; 0x1_0000] {
        &mut self.0
    }
}

/// The Scorpion controller card: memory, chips, latches and what they are
/// wired to.
#[derive(Debug)]
pub struct Board {
    memory: Memory,
    pages: [Page; 256],
    via: Via,
    acia: Acia,
    /// The 6551's next event as last computed, and whether the 6551 changed
    /// since: its receiver decodes the line to answer, which every access
    /// to any chip would otherwise pay for.
    acia_next: Option<u64>,
    /// [`Acia::host_byte_due`], as `acia_next`.
    acia_host_due: Option<u64>,
    acia_stale: bool,
    drive: u8,
    sense: u8,
    switches: u8,
    bumpers: u8,
    scene: Scene,
    motors: [Stepper; 4],
    /// The port B levels the stepper drivers last saw.
    port_b: u8,
    kim: Vec<KimSlot>,
    /// Bytes the host received and has not taken yet.
    inbox: Vec<HostByte>,
    via_line: Line,
    acia_line: Line,
    /// The OR of every device's interrupt output: the CPU's IRQ input.
    irq: Line,
    /// The earliest cycle at which a device raises its interrupt output by
    /// itself (`u64::MAX`: none).
    next_event: u64,
    /// Polls before this cycle have nothing to do: the IRQ line is released
    /// (and reads released for every cycle a poll can ask about) and no
    /// device event is due. 0 while the line is asserted or just changed.
    attention: u64,
    /// The cycle the IRQ line last changed.
    irq_changed_at: u64,
    /// The host watches its line: a byte reaching it ends the CPU's run
    /// ([`Board::watch_host`]).
    host_watch: bool,
    /// While watching, the next cycle to look for a byte reaching the host
    /// ([`Acia::host_byte_due`]); `u64::MAX` otherwise.
    host_due: u64,
    /// A byte reached the watching host and it has not taken it yet.
    host_arrived: bool,
    /// Something watching the bus asked the run to end at this
    /// instruction's end ([`Board::request_stop`]).
    stop_asked: bool,
    /// The cycle of the last poll.
    last_poll: u64,
    /// Addresses from here up to the ROM take the slow path (the I/O page,
    /// unconnected space, and KIM-bus pages holding a device); everything
    /// below, and the ROM, is plain memory.
    slow_start: u16,
    /// `$F000 - slow_start`: the length of the slow span, so that one
    /// wrapping subtraction and one comparison place an address.
    slow_span: u16,
    rom_writes: u64,
}

fn is_ram_address(address: u16) -> bool {
    address <= map::RAM_END || map::KIM_BUS.contains(&address)
}

impl Board {
    /// A board with `rom` (exactly 4 KiB) at `$F000`, RAM and KIM-bus RAM
    /// zeroed, nothing pressed, the switches at 9600 baud, and the host's
    /// line at 9600 baud 8N1.
    ///
    /// # Errors
    /// [`crate::Error::RomSize`] if `rom` is not 4096 bytes.
    pub fn new(rom: &[u8]) -> Result<Board, crate::Error> {
        if rom.len() != map::ROM_SIZE {
            return Err(crate::Error::RomSize { len: rom.len() });
        }
        let mut memory = Memory([0; 0x1_0000]);
        memory[usize::from(map::ROM_START)..].copy_from_slice(rom);
        let mut pages = [Page::Open; 256];
        for (index, page) in pages.iter_mut().enumerate() {
            let address = u16::try_from(index << 8).unwrap_or(0);
            *page = if is_ram_address(address) {
                Page::Ram
            } else if address >= map::ROM_START {
                Page::Rom
            } else if address == map::IO_START {
                Page::Io
            } else {
                Page::Open
            };
        }
        let mut board = Board {
            memory,
            pages,
            via: Via::new(),
            acia: Acia::new(),
            acia_next: None,
            acia_host_due: None,
            acia_stale: true,
            drive: 0,
            sense: 0,
            switches: map::DEFAULT_SWITCHES,
            bumpers: 0,
            scene: Scene::default(),
            motors: Default::default(),
            port_b: 0xFF,
            kim: Vec::new(),
            inbox: Vec::new(),
            via_line: Line::new(),
            acia_line: Line::new(),
            irq: Line::new(),
            next_event: u64::MAX,
            attention: 0,
            irq_changed_at: 0,
            host_watch: false,
            host_due: u64::MAX,
            host_arrived: false,
            stop_asked: false,
            last_poll: 0,
            slow_start: map::IO_START,
            slow_span: map::ROM_START - map::IO_START,
            rom_writes: 0,
        };
        board.set_bumpers(0, 0);
        Ok(board)
    }

    /// /RES at `cycle`: the chips and the drive latch go to their reset
    /// state (RAM keeps its contents, the world outside keeps its state).
    pub fn reset(&mut self, cycle: u64) {
        self.via.reset(cycle);
        self.acia_mut().reset(cycle);
        for slot in &mut self.kim {
            slot.device.sync(cycle);
        }
        self.drive = 0;
        self.update_port_b(cycle);
        self.refresh(cycle);
    }

    /// A copy of the board as it is now (memory, chips, latches, motors,
    /// scene, mapped devices, what the host has not taken yet), which runs
    /// on exactly as this one would; `None` if a mapped device cannot be
    /// copied ([`Device::snapshot`]).
    #[must_use]
    pub fn snapshot(&self) -> Option<Board> {
        let kim = self
            .kim
            .iter()
            .map(|slot| {
                Some(KimSlot {
                    start: slot.start,
                    end: slot.end,
                    device: slot.device.snapshot()?,
                    line: slot.line,
                })
            })
            .collect::<Option<Vec<_>>>()?;
        Some(Board {
            memory: self.memory.clone(),
            pages: self.pages,
            via: self.via.clone(),
            acia: self.acia.clone(),
            acia_next: self.acia_next,
            acia_host_due: self.acia_host_due,
            acia_stale: self.acia_stale,
            drive: self.drive,
            sense: self.sense,
            switches: self.switches,
            bumpers: self.bumpers,
            scene: self.scene.clone(),
            motors: self.motors.clone(),
            port_b: self.port_b,
            kim,
            inbox: self.inbox.clone(),
            via_line: self.via_line,
            acia_line: self.acia_line,
            irq: self.irq,
            next_event: self.next_event,
            attention: self.attention,
            irq_changed_at: self.irq_changed_at,
            host_watch: self.host_watch,
            host_due: self.host_due,
            host_arrived: self.host_arrived,
            stop_asked: self.stop_asked,
            last_poll: self.last_poll,
            slow_start: self.slow_start,
            slow_span: self.slow_span,
            rom_writes: self.rom_writes,
        })
    }

    /// Copies `bytes` into RAM (the card's or the KIM bus's) at `address`,
    /// as a loader or a test fixture does.
    ///
    /// # Errors
    /// [`crate::Error::NotRam`] if any byte would land outside RAM (the ROM,
    /// the I/O page, a KIM-bus device, past `$FFFF`).
    pub fn load(&mut self, address: u16, bytes: &[u8]) -> Result<(), crate::Error> {
        for offset in 0..bytes.len() {
            let at = usize::from(address) + offset;
            let fits = u16::try_from(at).is_ok_and(|at| self.is_plain_ram(at));
            if !fits {
                return Err(crate::Error::NotRam {
                    address: u16::try_from(at).unwrap_or(0xFFFF),
                    len: bytes.len(),
                });
            }
        }
        let start = usize::from(address);
        self.memory[start..start + bytes.len()].copy_from_slice(bytes);
        Ok(())
    }

    /// Whether `address` is RAM a loader may write: the card's RAM or
    /// KIM-bus RAM not taken by a mapped device.
    #[must_use]
    pub fn is_ram(&self, address: u16) -> bool {
        self.is_plain_ram(address)
    }

    fn is_plain_ram(&self, address: u16) -> bool {
        match self.pages[usize::from(address >> 8)] {
            Page::Ram => true,
            Page::Kim => !self
                .kim
                .iter()
                .any(|s| (s.start..=s.end).contains(&address)),
            _ => false,
        }
    }

    /// The bytes of memory (RAM, KIM-bus RAM and ROM; I/O and device
    /// addresses hold whatever was last loaded there, not register values).
    #[must_use]
    pub fn memory(&self) -> &[u8; 0x1_0000] {
        &self.memory
    }

    /// Maps `device` into the KIM-bus expansion space at `start..=end`.
    /// Its interrupt output joins the IRQ line.
    ///
    /// # Errors
    /// [`crate::Error::KimSlot`] if the range is empty, leaves
    /// `$1000-$BFFF` or overlaps a device already mapped.
    pub fn map_kim(
        &mut self,
        start: u16,
        end: u16,
        device: Box<dyn Device>,
    ) -> Result<KimSlotId, crate::Error> {
        let reason = if end < start {
            Some("the range is empty")
        } else if start < map::KIM_START || end > map::KIM_END {
            Some("KIM-bus devices live in $1000-$BFFF")
        } else if self
            .kim
            .iter()
            .any(|slot| start <= slot.end && slot.start <= end)
        {
            Some("it overlaps a device already mapped")
        } else {
            None
        };
        if let Some(reason) = reason {
            return Err(crate::Error::KimSlot { start, end, reason });
        }
        for page in (start >> 8)..=(end >> 8) {
            self.pages[usize::from(page)] = Page::Kim;
        }
        self.slow_start = self.slow_start.min(start & 0xFF00);
        self.slow_span = map::ROM_START - self.slow_start;
        self.kim.push(KimSlot {
            start,
            end,
            device,
            line: Line::new(),
        });
        self.refresh_next_event();
        Ok(KimSlotId(self.kim.len() - 1))
    }

    /// The device in a KIM-bus slot, as its concrete type.
    #[must_use]
    pub fn kim_device<D: Device>(&self, slot: KimSlotId) -> Option<&D> {
        self.kim.get(slot.0)?.device.as_any().downcast_ref::<D>()
    }

    /// The device in a KIM-bus slot, as its concrete type, mutable (for
    /// host-side changes; call [`Board::sync_kim`] after changing its
    /// interrupt output).
    pub fn kim_device_mut<D: Device>(&mut self, slot: KimSlotId) -> Option<&mut D> {
        self.kim
            .get_mut(slot.0)?
            .device
            .as_any_mut()
            .downcast_mut::<D>()
    }

    /// Tells the board that a KIM-bus device changed outside a bus access
    /// at `cycle` (its interrupt output or its next event).
    pub fn sync_kim(&mut self, slot: KimSlotId, cycle: u64) {
        if let Some(slot) = self.kim.get_mut(slot.0) {
            slot.device.sync(cycle);
        }
        self.refresh(cycle);
    }

    /// The first failure a KIM-bus device reported since the last call,
    /// with the base address of its slot.
    pub fn take_device_fault(
        &mut self,
    ) -> Option<(u16, Box<dyn miette::Diagnostic + Send + Sync>)> {
        self.kim
            .iter_mut()
            .find_map(|slot| slot.device.take_fault().map(|fault| (slot.start, fault)))
    }

    /// The 6522.
    #[must_use]
    pub fn via(&self) -> &Via {
        &self.via
    }

    /// The 6551 and the host end of the line.
    #[must_use]
    pub fn acia(&self) -> &Acia {
        &self.acia
    }

    /// The `DRIVE` latch as last written.
    #[must_use]
    pub fn drive_latch(&self) -> u8 {
        self.drive
    }

    /// A motor.
    #[must_use]
    pub fn motor(&self, motor: Motor) -> &Stepper {
        &self.motors[motor.index()]
    }

    /// A motor, mutable (to re-centre it).
    pub fn motor_mut(&mut self, motor: Motor) -> &mut Stepper {
        &mut self.motors[motor.index()]
    }

    /// Which eye lamps are lit: (left, right).
    #[must_use]
    pub fn eyes(&self) -> (bool, bool) {
        (
            self.drive & drive::LEFT_EYE != 0,
            self.drive & drive::RIGHT_EYE != 0,
        )
    }

    /// Whether the ground-tracker lamps are lit.
    #[must_use]
    pub fn lamps(&self) -> bool {
        self.drive & drive::LAMPS != 0
    }

    /// The tone the speaker plays, in hertz, or `None` when silent.
    #[must_use]
    pub fn speaker_hz(&self) -> Option<f64> {
        if self.drive & drive::SPEAKER == 0 {
            return None;
        }
        self.via.pb7_square_wave_hz(CPU_HZ)
    }

    /// Closed bumper microswitches, one bit each (1 = closed).
    #[must_use]
    pub fn bumpers(&self) -> u8 {
        self.bumpers
    }

    /// Closes the bumpers whose bits are set in `closed` and opens the
    /// others, at `cycle`. Closing the first one is a falling edge on CA1.
    pub fn set_bumpers(&mut self, closed: u8, cycle: u64) {
        self.catch_up(cycle);
        self.bumpers = closed;
        self.via.set_pa_pins(!closed, cycle);
        self.via.set_ca1(closed == 0, cycle);
        self.refresh(cycle);
    }

    /// Sets what the ground-tracker phototransistors see (`SENSE` bits:
    /// bit 0 right, bit 1 left).
    pub fn set_phototransistors(&mut self, lit: u8) {
        self.sense = lit & (map::sense::LEFT | map::sense::RIGHT);
    }

    /// The phototransistors as last set.
    #[must_use]
    pub fn phototransistors(&self) -> u8 {
        self.sense
    }

    /// Sets the configuration DIP switches (bits 0-3: the baud code the
    /// ROM programs into the 6551).
    pub fn set_switches(&mut self, switches: u8) {
        self.switches = switches;
    }

    /// The DIP switches.
    #[must_use]
    pub fn switches(&self) -> u8 {
        self.switches
    }

    /// What the infrared scanner sees.
    pub fn scene_mut(&mut self) -> &mut Scene {
        &mut self.scene
    }

    /// Replaces what the infrared scanner sees.
    pub fn set_scene(&mut self, scene: Scene) {
        self.scene = scene;
    }

    /// The scanners' current reading.
    #[must_use]
    pub fn scanner_reading(&self) -> u8 {
        self.scene.reading(
            self.motors[Motor::HorizontalScanner.index()].position(),
            self.motors[Motor::VerticalScanner.index()].position(),
        )
    }

    /// Sets the host's end of the serial line.
    pub fn set_host_line(&mut self, baud: Baud, format: FrameFormat) {
        self.acia_mut().set_host_line(baud, format);
    }

    /// The host sends `bytes`, back to back from `cycle` (or after what it
    /// sent before). Returns the cycle the last one ends.
    pub fn host_send(&mut self, bytes: &[u8], cycle: u64) -> u64 {
        self.catch_up(cycle);
        let mut end = self.acia.host_line_free_at();
        for &byte in bytes {
            end = self.acia_mut().host_send(byte, cycle);
        }
        self.refresh(cycle);
        end
    }

    /// What the host has received from the robot by `cycle` and not taken
    /// yet.
    pub fn host_receive(&mut self, cycle: u64) -> Vec<HostByte> {
        self.pull(cycle);
        std::mem::take(&mut self.inbox)
    }

    /// The bytes the host has received by `cycle` up to and including the
    /// first `end` byte, if one has arrived; later bytes stay for the next
    /// call.
    pub fn host_receive_until(&mut self, cycle: u64, end: u8) -> Option<Vec<HostByte>> {
        self.pull(cycle);
        let position = self.inbox.iter().position(|b| b.byte == end)?;
        let rest = self.inbox.split_off(position + 1);
        Some(std::mem::replace(&mut self.inbox, rest))
    }

    fn pull(&mut self, cycle: u64) {
        self.catch_up(cycle);
        let received = self.acia_mut().host_receive(cycle);
        self.inbox.extend(received);
        self.host_arrived = false;
        self.refresh(cycle);
    }

    /// The host watches its line (`true`) or not: while it does, a byte
    /// reaching it ends the CPU's run at the end of the instruction during
    /// which it arrived ([`crate::Stop::Bus`]), so the host can answer it
    /// as promptly as it likes instead of looking every so often; once
    /// the host has taken what arrived ([`Board::host_receive`]), runs go
    /// on. Ending a run changes nothing in what the robot does.
    pub fn watch_host(&mut self, watch: bool) {
        self.host_watch = watch;
        self.host_arrived = false;
        self.refresh_next_event();
    }

    /// Ends the CPU's run at the end of the instruction (or interrupt
    /// sequence) under way, with [`crate::Stop::Bus`], as a byte reaching
    /// a watching host does: for a bus wrapped around the board that saw
    /// an access it watches for (a debugger's watchpoint), so that the
    /// run needs no look of its own before every instruction. The next
    /// poll is made (whatever the devices' quiet), and sees it. Ending a
    /// run changes nothing in what the robot does. Stays asked until
    /// [`Board::clear_stop_request`].
    pub fn request_stop(&mut self) {
        self.stop_asked = true;
        self.attention = 0;
    }

    /// Forgets a [`Board::request_stop`]: runs go on.
    pub fn clear_stop_request(&mut self) {
        self.stop_asked = false;
    }

    /// Attempted writes to the ROM since power-up (they change nothing).
    #[must_use]
    pub fn rom_writes(&self) -> u64 {
        self.rom_writes
    }

    /// Whether a read of `address` is a plain memory read (outside
    /// `slow_start..$F000`): one subtraction and one comparison, so that
    /// fetches and RAM accesses cost about what they cost on a RAM bus.
    #[inline(always)]
    fn is_plain_read(&self, address: u16) -> bool {
        address.wrapping_sub(self.slow_start) >= self.slow_span
    }

    /// Whether a write to `address` is a plain memory write (the ROM is
    /// not: a write there is counted and dropped).
    #[inline(always)]
    fn is_plain_write(&self, address: u16) -> bool {
        address < self.slow_start
    }

    /// The 6551, to change it: its next event will be computed afresh.
    fn acia_mut(&mut self) -> &mut Acia {
        self.acia_stale = true;
        &mut self.acia
    }

    /// [`Device::next_event`] of the 6551, computed again only after it
    /// changed (it depends on nothing else).
    fn acia_next_event(&mut self) -> Option<u64> {
        self.refresh_acia();
        self.acia_next
    }

    /// [`Acia::host_byte_due`], kept like its next event.
    fn acia_host_byte_due(&mut self) -> Option<u64> {
        self.refresh_acia();
        self.acia_host_due
    }

    fn refresh_acia(&mut self) {
        if self.acia_stale {
            self.acia_next = self.acia.next_event();
            self.acia_host_due = self.acia.host_byte_due();
            self.acia_stale = false;
        }
    }

    /// Processes every device event up to `cycle`, each at its own cycle.
    fn catch_up(&mut self, cycle: u64) {
        while self.next_event <= cycle {
            let at = self.next_event;
            if self.via.next_event().is_some_and(|e| e <= at) {
                self.via.sync(at);
            }
            if self.acia_next_event().is_some_and(|e| e <= at) {
                self.acia_mut().sync(at);
            }
            for slot in &mut self.kim {
                if slot.device.next_event().is_some_and(|e| e <= at) {
                    slot.device.sync(at);
                }
            }
            self.refresh(at);
        }
    }

    /// Records the devices' interrupt outputs at `cycle` and finds the next
    /// event.
    fn refresh(&mut self, cycle: u64) {
        self.via_line.set(self.via.irq(), cycle);
        self.acia_line.set(self.acia.irq(), cycle);
        let mut any = self.via_line.is_asserted() || self.acia_line.is_asserted();
        for slot in &mut self.kim {
            slot.line.set(slot.device.irq(), cycle);
            any |= slot.line.is_asserted();
        }
        if any != self.irq.is_asserted() {
            self.irq_changed_at = cycle;
        }
        self.irq.set(any, cycle);
        self.refresh_next_event();
    }

    fn refresh_next_event(&mut self) {
        let mut next = self.via.next_event().unwrap_or(u64::MAX);
        next = next.min(self.acia_next_event().unwrap_or(u64::MAX));
        for slot in &self.kim {
            next = next.min(slot.device.next_event().unwrap_or(u64::MAX));
        }
        self.next_event = next;
        self.host_due = if self.host_watch {
            self.acia_host_byte_due().unwrap_or(u64::MAX)
        } else {
            u64::MAX
        };
        self.set_attention();
    }

    /// Lets polls skip all work until the next device event, unless the IRQ
    /// line is asserted or changed after the last poll (a poll may still
    /// ask about a cycle before the change).
    fn set_attention(&mut self) {
        self.attention = if self.irq.is_asserted() || self.irq_changed_at > self.last_poll {
            0
        } else {
            self.next_event.min(self.host_due)
        };
    }

    #[cold]
    #[inline(never)]
    fn poll_slow(&mut self, cycle: u64) -> Interrupts {
        if cycle >= self.next_event {
            self.catch_up(cycle);
        }
        if cycle >= self.host_due {
            // A byte on its way to the watching host: has it arrived?
            self.acia_mut().sync(cycle);
            self.refresh_next_event();
            self.host_arrived |= self.host_due <= cycle;
        }
        self.last_poll = cycle;
        let irq = self.irq.at(cycle);
        self.set_attention();
        Interrupts { irq, nmi: false }
    }

    /// Feeds the port B levels and the driver enables to the stepper
    /// drivers.
    fn update_port_b(&mut self, cycle: u64) {
        let level = self.via.pb_level();
        self.port_b = level;
        for motor in Motor::ALL {
            let (step, dir, enable) = motor.wiring();
            self.motors[motor.index()].drive(
                level & step != 0,
                level & dir != 0,
                self.drive & enable != 0,
                cycle,
            );
        }
    }

    fn io_read(&mut self, address: u16, cycle: u64) -> u8 {
        self.catch_up(cycle);
        match address {
            map::VIA..=map::VIA_END => {
                let value = self.via.read(address - map::VIA, cycle);
                self.refresh(cycle);
                value
            }
            map::ACIA..=map::ACIA_END => {
                let value = self.acia_mut().read(address - map::ACIA, cycle);
                self.refresh(cycle);
                value
            }
            map::DRIVE => self.drive,
            map::SENSE => self.sense,
            map::SWITCHES => self.switches,
            map::SCANNER => self.scanner_reading(),
            _ => map::OPEN_BUS,
        }
    }

    fn io_write(&mut self, address: u16, value: u8, cycle: u64) {
        self.catch_up(cycle);
        match address {
            map::VIA..=map::VIA_END => {
                let register = address - map::VIA;
                self.via.write(register, value, cycle);
                if matches!(
                    register,
                    via::reg::ORB | via::reg::DDRB | via::reg::ACR | via::reg::T1C_H
                ) {
                    self.update_port_b(cycle);
                }
                self.refresh(cycle);
            }
            map::ACIA..=map::ACIA_END => {
                self.acia_mut().write(address - map::ACIA, value, cycle);
                self.refresh(cycle);
            }
            map::DRIVE => {
                self.drive = value;
                self.update_port_b(cycle);
            }
            _ => {}
        }
    }

    /// [`Bus::peek`] of an address that is not memory.
    #[cold]
    #[inline(never)]
    fn peek_device(&self, address: u16) -> u8 {
        match self.pages[usize::from(address >> 8)] {
            Page::Ram | Page::Rom => self.memory[usize::from(address)],
            Page::Io => self.io_peek(address),
            Page::Kim => match self.kim_slot(address) {
                Some(index) => {
                    let slot = &self.kim[index];
                    slot.device.peek(address - slot.start)
                }
                None => self.memory[usize::from(address)],
            },
            Page::Open => (address >> 8) as u8,
        }
    }

    fn io_peek(&self, address: u16) -> u8 {
        match address {
            map::VIA..=map::VIA_END => self.via.peek(address - map::VIA),
            map::ACIA..=map::ACIA_END => self.acia.peek(address - map::ACIA),
            map::DRIVE => self.drive,
            map::SENSE => self.sense,
            map::SWITCHES => self.switches,
            map::SCANNER => self.scanner_reading(),
            _ => map::OPEN_BUS,
        }
    }

    /// Whether `address` is a KIM-bus device's stable register
    /// ([`Device::is_stable`]).
    fn is_stable_device_read(&self, address: u16) -> bool {
        self.pages[usize::from(address >> 8)] == Page::Kim
            && self.kim_slot(address).is_some_and(|index| {
                let slot = &self.kim[index];
                slot.device.is_stable(address - slot.start)
            })
    }

    fn kim_slot(&self, address: u16) -> Option<usize> {
        self.kim
            .iter()
            .position(|slot| (slot.start..=slot.end).contains(&address))
    }

    #[cold]
    #[inline(never)]
    fn slow_read(&mut self, address: u16, cycle: u64) -> u8 {
        match self.pages[usize::from(address >> 8)] {
            Page::Io => self.io_read(address, cycle),
            Page::Kim => match self.kim_slot(address) {
                Some(index) => {
                    self.catch_up(cycle);
                    let slot = &mut self.kim[index];
                    let value = slot.device.read(address - slot.start, cycle);
                    self.refresh(cycle);
                    value
                }
                None => self.memory[usize::from(address)],
            },
            Page::Open => (address >> 8) as u8,
            Page::Ram | Page::Rom => self.memory[usize::from(address)],
        }
    }

    #[cold]
    #[inline(never)]
    fn slow_write(&mut self, address: u16, value: u8, cycle: u64) {
        match self.pages[usize::from(address >> 8)] {
            Page::Io => self.io_write(address, value, cycle),
            Page::Kim => match self.kim_slot(address) {
                Some(index) => {
                    self.catch_up(cycle);
                    let slot = &mut self.kim[index];
                    slot.device.write(address - slot.start, value, cycle);
                    self.refresh(cycle);
                }
                None => self.memory[usize::from(address)] = value,
            },
            Page::Rom => self.rom_writes += 1,
            Page::Open => {}
            Page::Ram => self.memory[usize::from(address)] = value,
        }
    }
}

impl Bus for Board {
    #[inline(always)]
    fn read(&mut self, address: u16, cycle: u64) -> u8 {
        if self.is_plain_read(address) {
            self.memory[usize::from(address)]
        } else {
            self.slow_read(address, cycle)
        }
    }

    #[inline(always)]
    fn write(&mut self, address: u16, value: u8, cycle: u64) {
        if self.is_plain_write(address) {
            self.memory[usize::from(address)] = value;
        } else {
            self.slow_write(address, value, cycle);
        }
    }

    #[inline(always)]
    fn read_zp_stack(&mut self, address: u16, _cycle: u64) -> u8 {
        // $0000-$01FF is the card's RAM, always (KIM-bus devices start at
        // $1000).
        self.memory[usize::from(address)]
    }

    #[inline(always)]
    fn write_zp_stack(&mut self, address: u16, value: u8, _cycle: u64) {
        self.memory[usize::from(address)] = value;
    }

    #[inline(always)]
    fn dummy_read(&mut self, address: u16, cycle: u64) {
        // Reading memory has no effect: only device addresses are visited.
        if !self.is_plain_read(address) {
            self.slow_read(address, cycle);
        }
    }

    // Inlined: a profiler peeks at every opcode, which is memory; the
    // devices' peeks stay out of line.
    #[inline(always)]
    fn peek(&self, address: u16) -> u8 {
        match self.pages[usize::from(address >> 8)] {
            Page::Ram | Page::Rom => self.memory[usize::from(address)],
            _ => self.peek_device(address),
        }
    }

    #[inline(always)]
    fn poll(&mut self, cycle: u64) -> Interrupts {
        // One comparison per instruction while nothing happens.
        if cycle < self.attention {
            return Interrupts::NONE;
        }
        self.poll_slow(cycle)
    }

    #[inline(always)]
    fn quiet_until(&self) -> u64 {
        // Below `attention` a poll returns NONE without touching anything
        // (see `poll`); NMI is not connected.
        self.attention
    }

    #[inline(always)]
    fn stop_requested(&self) -> bool {
        self.host_arrived | self.stop_asked
    }

    #[inline(always)]
    fn is_plain_memory(&self, address: u16) -> bool {
        // RAM, KIM-bus RAM and the ROM, and a KIM-bus device's stable
        // registers (their values change only at the device's events,
        // which bound a skip like every event); not the I/O page or
        // unconnected space.
        self.is_plain_read(address) || self.is_stable_device_read(address)
    }

    #[inline(always)]
    fn is_plain_store(&self, address: u16) -> bool {
        // RAM and KIM-bus RAM below the I/O page.
        self.is_plain_write(address)
    }
}

/// The virtual Scorpion: the controller card with its CPU, and the host's
/// side of the robot.
pub type Scorpion = Machine<Board>;

impl Machine<Board> {
    /// A copy of the robot as it is now, CPU and board
    /// ([`Board::snapshot`]); `None` if a mapped device cannot be copied.
    #[must_use]
    pub fn snapshot(&self) -> Option<Scorpion> {
        Some(Machine {
            cpu: self.cpu.clone(),
            bus: self.bus.snapshot()?,
        })
    }

    /// A powered-up Scorpion running `rom` (4 KiB, loaded at `$F000`).
    ///
    /// # Errors
    /// [`crate::Error::RomSize`] if `rom` is not 4096 bytes.
    pub fn scorpion(rom: &[u8]) -> Result<Scorpion, crate::Error> {
        let mut scorpion = Machine::new(Board::new(rom)?);
        scorpion.power_on();
        Ok(scorpion)
    }

    /// The reset button: /RES to the chips and the CPU.
    pub fn power_on(&mut self) {
        let cycle = self.cpu.cycles();
        self.bus.reset(cycle);
        self.reset();
    }

    /// The card.
    #[must_use]
    pub fn board(&self) -> &Board {
        &self.bus
    }

    /// The card, mutable.
    pub fn board_mut(&mut self) -> &mut Board {
        &mut self.bus
    }

    /// The current cycle.
    #[must_use]
    pub fn now(&self) -> u64 {
        self.cpu.cycles()
    }

    /// Closes the bumpers whose bits are set in `closed`, now.
    pub fn set_bumpers(&mut self, closed: u8) {
        let now = self.now();
        self.bus.set_bumpers(closed, now);
    }

    /// Sets the host's serial line to `bits_per_second`, 8N1.
    pub fn set_baud(&mut self, bits_per_second: u32) {
        self.bus
            .set_host_line(Baud::new(bits_per_second), FrameFormat::EIGHT_N_ONE);
    }

    /// The host sends `bytes` back to back from now (or after what it sent
    /// before). Returns the cycle the last one ends on the wire.
    pub fn send(&mut self, bytes: &[u8]) -> u64 {
        let now = self.now();
        self.bus.host_send(bytes, now)
    }

    /// What the host has received since it last asked.
    pub fn receive(&mut self) -> Vec<u8> {
        self.receive_detailed().iter().map(|b| b.byte).collect()
    }

    /// [`Scorpion::receive`] with the cycle of each byte and its line errors.
    pub fn receive_detailed(&mut self) -> Vec<HostByte> {
        let now = self.now();
        self.bus.host_receive(now)
    }

    /// What the host has received up to and including the first `end`
    /// byte, if one has arrived by now; bytes after it stay for the next
    /// call. The wire knows no protocol: the host side (romlib's
    /// `VirtualScorpion`) says which byte ends an answer.
    pub fn receive_until(&mut self, end: u8) -> Option<Vec<u8>> {
        let now = self.now();
        self.bus
            .host_receive_until(now, end)
            .map(|bytes| bytes.iter().map(|b| b.byte).collect())
    }

    /// The cycle the last byte the host sent ends on the wire (now or
    /// earlier if the line is idle).
    #[must_use]
    pub fn host_line_free_at(&self) -> u64 {
        self.bus.acia().host_line_free_at().max(self.now())
    }

    /// Maps a device into the KIM-bus space (see [`Board::map_kim`]).
    ///
    /// # Errors
    /// As [`Board::map_kim`].
    pub fn map_kim(
        &mut self,
        start: u16,
        end: u16,
        device: Box<dyn Device>,
    ) -> Result<KimSlotId, crate::Error> {
        self.bus.map_kim(start, end, device)
    }

    /// The baud code the ROM reads from the switches for `bits_per_second`,
    /// set on the switches (`None` if the 6551 has no such rate).
    pub fn set_switch_baud(&mut self, bits_per_second: u32) -> Option<u8> {
        let code = acia::baud_code(bits_per_second)?;
        let switches = (self.bus.switches() & 0xF0) | code;
        self.bus.set_switches(switches);
        Some(code)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::board::via::irq;

    /// A ROM whose reset code is `program` at `$F000`, IRQ vector at
    /// `irq_handler` (an offset into the ROM), reset vector `$F000`.
    fn rom_with(program: &[u8], irq_at: usize, irq_handler: &[u8]) -> Vec<u8> {
        let mut rom = vec![0xEA; map::ROM_SIZE];
        rom[..program.len()].copy_from_slice(program);
        rom[irq_at..irq_at + irq_handler.len()].copy_from_slice(irq_handler);
        let irq_address = 0xF000 + u16::try_from(irq_at).expect("in the ROM");
        rom[0xFFC] = 0x00;
        rom[0xFFD] = 0xF0;
        rom[0xFFE] = (irq_address & 0xFF) as u8;
        rom[0xFFF] = (irq_address >> 8) as u8;
        rom
    }

    #[test]
    fn memory_map_ram_rom_io_and_open_bus() {
        // LDA #$42 / STA $0300 / STA $F900 / STA $2000 / JMP *
        let program = [
            0xA9, 0x42, 0x8D, 0x00, 0x03, 0x8D, 0x00, 0xF9, 0x8D, 0x00, 0x20, 0x4C, 0x0B, 0xF0,
        ];
        let mut scorpion =
            Scorpion::scorpion(&rom_with(&program, 0x800, &[0x40])).expect("a 4 KiB ROM");
        scorpion.run(100);
        let board = scorpion.board();
        assert_eq!(board.peek(0x0300), 0x42);
        assert_eq!(board.peek(0x2000), 0x42, "KIM-bus RAM");
        assert_eq!(board.peek(0xF900), 0xEA, "the ROM is write-protected");
        assert_eq!(board.rom_writes(), 1);
        assert_eq!(board.peek(0xC0FF), map::OPEN_BUS);
        assert_eq!(board.peek(0xD123), 0xD1);
        assert_eq!(board.peek(map::SWITCHES), map::DEFAULT_SWITCHES);
    }

    #[test]
    fn rom_must_be_4_kib_and_loads_stay_in_ram() {
        assert!(matches!(
            Board::new(&[0; 100]),
            Err(crate::Error::RomSize { len: 100 })
        ));
        let mut board = Board::new(&[0; 4096]).expect("a 4 KiB ROM");
        board.load(0x0400, &[1, 2, 3]).expect("user RAM");
        board.load(0xBFFE, &[1, 2]).expect("the top of the KIM bus");
        assert!(board.load(0xBFFF, &[1, 2]).is_err());
        assert!(board.load(0xF000, &[1]).is_err());
    }

    #[test]
    fn a_via_timer_interrupts_the_cpu_at_its_time() {
        // Reset: T1 one-shot of 1000 cycles with its interrupt enabled,
        // CLI, then count in X forever. IRQ: read T1C-L (clears the flag),
        // store the count, INC $10, RTI.
        let program = [
            0xA9, 0xC0, 0x8D, 0x0E, 0xC0, // LDA #$C0 / STA IER
            0xA9, 0xE8, 0x8D, 0x04, 0xC0, // LDA #<1000 / STA T1C-L
            0xA9, 0x03, 0x8D, 0x05, 0xC0, // LDA #>1000 / STA T1C-H
            0x58, // CLI
            0xE8, 0x4C, 0x10, 0xF0, // loop: INX / JMP loop
        ];
        let handler = [0xAD, 0x04, 0xC0, 0x86, 0x11, 0xE6, 0x10, 0x40];
        let mut scorpion =
            Scorpion::scorpion(&rom_with(&program, 0x800, &handler)).expect("a 4 KiB ROM");
        scorpion.run(900);
        assert_eq!(scorpion.board().peek(0x10), 0);
        scorpion.run(1100);
        assert_eq!(scorpion.board().peek(0x10), 1, "one interrupt");
        scorpion.run(100_000);
        assert_eq!(scorpion.board().peek(0x10), 1, "a one-shot fires once");
        assert!(!scorpion.board().via().irq());
        assert_eq!(scorpion.board().via().flags() & irq::T1, 0);
    }

    #[test]
    fn serial_bytes_reach_the_cpu_and_answers_reach_the_host() {
        // An echo program that polls the 6551: set 9600 8N1, DTR, TX on;
        // loop: wait for RDRF, read, wait for TDRE, write.
        let program = [
            0xA9, 0x1E, 0x8D, 0x13, 0xC0, // LDA #$1E / STA control
            0xA9, 0x0B, 0x8D, 0x12, 0xC0, // LDA #$0B / STA command
            0xAD, 0x11, 0xC0, 0x29, 0x08, 0xF0, 0xF9, // wait RDRF
            0xAE, 0x10, 0xC0, // LDX data
            0xAD, 0x11, 0xC0, 0x29, 0x10, 0xF0, 0xF9, // wait TDRE
            0x8E, 0x10, 0xC0, // STX data
            0x4C, 0x0A, 0xF0,
        ];
        let mut scorpion =
            Scorpion::scorpion(&rom_with(&program, 0x800, &[0x40])).expect("a 4 KiB ROM");
        scorpion.run(50);
        scorpion.send(b"/1X\r");
        let mut answer = None;
        while answer.is_none() && scorpion.now() < 1_000_000 {
            scorpion.run(scorpion.now() + 100);
            answer = scorpion.receive_until(b'\r');
        }
        assert_eq!(answer, Some(b"/1X\r".to_vec()));
        // Four characters at 9600 baud take about 4.2 ms; the echo ends
        // one character later.
        assert!(
            (4_000..6_500).contains(&scorpion.now()),
            "{}",
            scorpion.now()
        );
    }

    #[test]
    fn step_pulses_move_the_motors_only_when_enabled() {
        let mut board = Board::new(&[0; 4096]).expect("a 4 KiB ROM");
        board.write(0xC002, 0xFF, 1); // DDRB all outputs
        board.write(0xC000, 0x00, 2);
        for cycle in 0..5u64 {
            board.write(0xC000, port_b::LEFT_STEP | port_b::LEFT_DIR, 10 + 4 * cycle);
            board.write(0xC000, 0x00, 12 + 4 * cycle);
        }
        assert_eq!(board.motor(Motor::Left).steps(), 0, "driver disabled");
        board.write(map::DRIVE, drive::LEFT_MOTOR | drive::RIGHT_MOTOR, 100);
        for cycle in 0..5u64 {
            board.write(
                0xC000,
                port_b::LEFT_STEP | port_b::LEFT_DIR | port_b::RIGHT_STEP,
                110 + 4 * cycle,
            );
            board.write(0xC000, 0x00, 112 + 4 * cycle);
        }
        assert_eq!(board.motor(Motor::Left).position(), 5);
        assert_eq!(board.motor(Motor::Right).position(), -5);
        assert_eq!(board.motor(Motor::HorizontalScanner).steps(), 0);
    }

    #[test]
    fn bumpers_read_low_and_fall_on_ca1() {
        let mut board = Board::new(&[0; 4096]).expect("a 4 KiB ROM");
        board.write(0xC00E, 0x80 | irq::CA1, 0);
        assert_eq!(board.read(0xC001, 1), 0xFF);
        board.set_bumpers(0b0000_0100, 10);
        assert_eq!(board.read(0xC00F, 11), 0b1111_1011);
        assert!(board.poll(12).irq, "closing a bumper interrupts");
        board.read(0xC001, 13);
        assert!(!board.poll(14).irq);
        // A second bumper while the first is closed: no new edge.
        board.set_bumpers(0b0000_0110, 20);
        assert!(!board.poll(21).irq);
    }

    #[test]
    fn scanner_reading_follows_the_scanner_position() {
        let mut board = Board::new(&[0; 4096]).expect("a 4 KiB ROM");
        board.set_scene(Scene::from_fn(|h, v| {
            u8::try_from((h + 50) + 2 * (v + 10)).unwrap_or(0)
        }));
        assert_eq!(board.read(map::SCANNER, 0), 70);
        board.write(0xC002, 0xFF, 1);
        board.write(map::DRIVE, drive::H_SCANNER | drive::V_SCANNER, 2);
        for step in 0..3u64 {
            board.write(0xC000, port_b::H_STEP, 10 + 2 * step);
            board.write(0xC000, 0, 11 + 2 * step);
        }
        board.write(0xC000, port_b::V_STEP | port_b::SCAN_DIR, 30);
        assert_eq!(board.motor(Motor::HorizontalScanner).position(), -3);
        assert_eq!(board.read(map::SCANNER, 31), 67 + 2);
    }

    #[test]
    fn speaker_plays_timer_1_on_pb7_through_the_amplifier() {
        let mut board = Board::new(&[0; 4096]).expect("a 4 KiB ROM");
        board.write(0xC00B, 0xC0, 0);
        board.write(0xC004, 0xF2, 1);
        board.write(0xC005, 0x01, 2); // 498 + 2 = 500-cycle half period
        assert_eq!(board.speaker_hz(), None, "the amplifier is off");
        board.write(map::DRIVE, drive::SPEAKER, 3);
        assert_eq!(board.speaker_hz(), Some(1000.0));
    }

    #[derive(Debug, Default)]
    struct Card {
        registers: [u8; 4],
        irq: bool,
    }

    impl Device for Card {
        fn read(&mut self, offset: u16, _cycle: u64) -> u8 {
            self.registers[usize::from(offset & 3)]
        }
        fn write(&mut self, offset: u16, value: u8, _cycle: u64) {
            self.registers[usize::from(offset & 3)] = value;
            self.irq = value == 0xFF;
        }
        fn irq(&self) -> bool {
            self.irq
        }
        fn as_any(&self) -> &dyn std::any::Any {
            self
        }
        fn as_any_mut(&mut self) -> &mut dyn std::any::Any {
            self
        }
    }

    #[test]
    fn kim_bus_devices_take_their_addresses_and_the_irq_line() {
        let mut board = Board::new(&[0; 4096]).expect("a 4 KiB ROM");
        let slot = board
            .map_kim(0x8000, 0x8003, Box::new(Card::default()))
            .expect("free KIM-bus space");
        assert!(
            board
                .map_kim(0x8002, 0x8010, Box::new(Card::default()))
                .is_err()
        );
        assert!(
            board
                .map_kim(0xC000, 0xC003, Box::new(Card::default()))
                .is_err()
        );
        board.write(0x8001, 0x5A, 1);
        board.write(0x8004, 0x77, 2);
        assert_eq!(board.read(0x8001, 3), 0x5A);
        assert_eq!(board.peek(0x8004), 0x77, "the rest of the page is RAM");
        assert_eq!(
            board.kim_device::<Card>(slot).map(|c| c.registers[1]),
            Some(0x5A)
        );
        board.write(0x8000, 0xFF, 4);
        assert!(board.poll(5).irq);
    }
}
