//! Crowded and large rooms (issue 28, the hostile pass's findings), each
//! against a peer measured in the same run, so the figures are ratios
//! that hold on any machine:
//!
//! - a scan (`/3H99`) while the robot turns on the spot among 1,000
//!   obstacles close round it, against the same scan in the empty room
//!   (walls only), as host time per robot second;
//! - an obstacle dragged in a room of 10,000 obstacles close round the
//!   robot (the room takes the edit and looks again), against the same
//!   drag in a room of one obstacle;
//! - the path's picture of a 2 km room as a PNG (at most `MAX_SIDE`
//!   pixels a side), against the picture of the 3 m example room.
//!
//! `cargo bench -p cards --bench rooms`.
#![allow(clippy::print_stdout, reason = "a benchmark reports on stdout")]

use std::fmt::Write as _;
use std::time::Instant;

use cards::Room;
use cards::room::geometry::Point;
use cards::room::live::Edit;

const ROUNDS: usize = 3;

/// A room of 30 by 30 metres with the robot in its middle and `count`
/// obstacles (circles and triangles, half a centimetre across) scattered
/// 40 to 250 cm round it: the hostile tester's crowd.
fn crowd(count: usize) -> String {
    let mut text = String::from("walls = [[0, 0], [3000, 0], [3000, 3000], [0, 3000]]\n");
    let mut seed: u64 = 1;
    let mut next = || {
        seed = seed
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    for k in 0..count {
        let (angle, far) = (next() * std::f64::consts::TAU, 40.0 + next() * 210.0);
        let (x, y) = (1500.0 + far * angle.cos(), 1500.0 + far * angle.sin());
        if k % 2 == 1 {
            let _ = writeln!(
                text,
                "[[obstacle]]\ncircle = {{ x = {x:.3}, y = {y:.3}, radius = 0.5 }}"
            );
        } else {
            let _ = writeln!(
                text,
                "[[obstacle]]\npolygon = [[{x:.3}, {y:.3}], [{:.3}, {y:.3}], [{x:.3}, {:.3}]]",
                x + 0.5,
                y + 0.5
            );
        }
    }
    text.push_str("[robot]\nx = 1500\ny = 1500\n");
    text
}

/// Host seconds per robot second of `world` with the reference ROM
/// scanning (`/3H99`) while both drives turn the robot on the spot.
fn scan_turning(world: &str) -> f64 {
    const CYCLES: u64 = 2_000_000;
    let mut robot = romlib::VirtualScorpion::new();
    robot.set_surroundings(Box::new(Room::load("room.toml", world).expect("loads")));
    robot.send(b"/4C+40/4D-40/3H99");
    let start = Instant::now();
    robot.run_for(CYCLES).expect("runs");
    start.elapsed().as_secs_f64() / (CYCLES as f64 / 1e6)
}

/// Host seconds one drag of an obstacle takes in `world` (the room takes
/// it at once, as the view has it), the mean of a few.
fn drag(world: &str) -> f64 {
    const DRAGS: u32 = 10;
    let room = Room::load("room.toml", world).expect("loads");
    let view = room.view();
    let mut robot = romlib::VirtualScorpion::new();
    robot.set_surroundings(Box::new(room));
    robot.run_for(10_000).expect("runs");
    let start = Instant::now();
    for k in 0..DRAGS {
        let to = Point::new(1800.0, 1500.0 + f64::from(k));
        assert!(view.edit(Edit::MoveObstacle { index: 1, to }));
        robot.run_for(0).expect("runs");
    }
    start.elapsed().as_secs_f64() / f64::from(DRAGS)
}

/// Host seconds to make the PNG of `world`'s path (a second of driving).
fn png(world: &str) -> (f64, usize) {
    let room = Room::load("room.toml", world).expect("loads");
    let view = room.view();
    let mut robot = romlib::VirtualScorpion::new();
    robot.set_surroundings(Box::new(room));
    robot.send(b"/4C+40/4D+40");
    robot.run_for(1_000_000).expect("runs");
    let start = Instant::now();
    let bytes = view
        .picture_for(std::path::Path::new("path.png"), &[])
        .expect("a PNG");
    (start.elapsed().as_secs_f64(), bytes.len())
}

const EXAMPLE: &str = include_str!("../../examples/room/room.toml");

/// A room of 2 km a side, a floor line 1 m wide across it.
const HUGE: &str =
    "walls = [[-100000, -100000], [100000, -100000], [100000, 100000], [-100000, 100000]]
[[line]]
points = [[-100000, -100000], [100000, 100000]]
width = 100
[robot]
x = 100
y = 300
";

fn main() {
    let (empty, crowded_1k, crowded_10k) = (crowd(0), crowd(1_000), crowd(10_000));
    let (mut scan_empty, mut scan_crowd) = (f64::MAX, f64::MAX);
    let (mut drag_one, mut drag_crowd) = (f64::MAX, f64::MAX);
    let (mut png_small, mut png_huge) = ((f64::MAX, 0), (f64::MAX, 0));
    for _ in 0..ROUNDS {
        scan_empty = scan_empty.min(scan_turning(&empty));
        scan_crowd = scan_crowd.min(scan_turning(&crowded_1k));
        drag_one = drag_one.min(drag(&crowd(2)));
        drag_crowd = drag_crowd.min(drag(&crowded_10k));
        let small = png(EXAMPLE);
        if small.0 < png_small.0 {
            png_small = small;
        }
        let huge = png(HUGE);
        if huge.0 < png_huge.0 {
            png_huge = huge;
        }
    }
    println!("crowded and large rooms (best of {ROUNDS}, each against its peer in this run)");
    println!(
        "  scan while turning, 1,000 obstacles close by: {:.1} ms a robot second, the empty room {:.1} ms: {:.1}x",
        scan_crowd * 1e3,
        scan_empty * 1e3,
        scan_crowd / scan_empty
    );
    println!(
        "  an obstacle dragged among 10,000: {:.2} ms, among 2: {:.3} ms: {:.0}x",
        drag_crowd * 1e3,
        drag_one * 1e3,
        drag_crowd / drag_one
    );
    println!(
        "  the PNG of a 2 km room: {:.0} ms ({} KiB), of the 3 m example room: {:.0} ms ({} KiB): {:.1}x",
        png_huge.0 * 1e3,
        png_huge.1 / 1024,
        png_small.0 * 1e3,
        png_small.1 / 1024,
        png_huge.0 / png_small.0
    );
}
