#!/usr/bin/env bash
# The main job, on the virtual Scorpion: build an extension from
# examples/ with our assembler and linker, rehearse it, upload it (every
# byte verified, the hook switched last), and ask the robot the new
# command. No hardware: `--port emu` is the emulated robot in the process.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
# The binary is built first, in the open: on a first run that takes a few
# minutes, and cargo's progress (on stderr) shows it is under way. The
# versions are the ones the tests ran with (Cargo.lock, --locked).
echo "building scorpion (release; minutes the first time, cargo's progress below)..." >&2
cargo build --release --locked --manifest-path "$repo/Cargo.toml" --bin scorpion
scorpion() { cargo run --quiet --release --locked --manifest-path "$repo/Cargo.toml" --bin scorpion -- "$@"; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"

echo "== build examples/checksum (a /9K command: the sum of a memory range)"
scorpion build "$repo/examples/checksum/checksum.s" \
    --target "$repo/examples/checksum/checksum.toml" -o checksum.elf
echo
echo "== rehearse, upload, verify, ask (demo/checksum.expect)"
scorpion upload checksum.elf --port emu --expect "$repo/demo/checksum.expect"
