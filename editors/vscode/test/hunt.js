// docs/DEBUGGING.md's bug hunt in VS Code terms: the planted bug in a copy
// of the checksum example (`bcc @carried` turned into `bcs @carried`)
// hunted through the extension's debugger contribution with VS Code's DAP
// test client, step for step as the guide walks it in the monitor: the
// wrong answer, a breakpoint on the branch only when the carry is clear, a
// step that shows the branch falling through to the `INC`, a step back,
// the opcode mended in place and the right answer. Each step prints the
// DAP requests it made.
// Usage: node test/hunt.js SCORPION_BINARY PROJECT_DIR (the copy, bug planted)
'use strict';
const assert = require('assert');
const fs = require('fs');
const path = require('path');
const { DebugClient } = require('@vscode/debugadapter-testsupport');

const [scorpion, project] = process.argv.slice(2);
if (!scorpion || !project) throw new Error('usage: node test/hunt.js SCORPION_BINARY PROJECT_DIR');

const manifest = JSON.parse(fs.readFileSync(path.join(__dirname, '..', 'package.json'), 'utf8'));
const contribution = manifest.contributes.debuggers.find((d) => d.type === 'scorpion');
// The first snippet's configuration, on the project's folder.
const launch = JSON.parse(
  JSON.stringify(contribution.configurationSnippets[0].body)
    .replace(/\^\\"\\\\\$\{workspaceFolder\}\\"/g, JSON.stringify(project).slice(1, -1))
    .replace(/\$\{\d+:([^}]*)\}/g, '$1'),
);
assert.equal(launch.program, project);
assert.equal(launch.stopOnEntry, true);

const source = path.join(project, 'checksum.s');
const lines = fs.readFileSync(source, 'utf8').split('\n');
const branch = lines.findIndex((l) => l.trim() === 'bcs @carried') + 1;
assert.ok(branch > 0, 'the bug is planted: `bcs @carried`');

const step = (what, requests) => console.log(`hunt: ${what} [${requests}]`);

// Output events until the robot's answer (a line starting `K`) is whole.
function answer(dc) {
  return new Promise((resolve) => {
    let text = '';
    const seen = (event) => {
      if (event.body.category !== 'stdout') return;
      text += event.body.output;
      const found = text.match(/K[0-9A-F]{4}\n/);
      if (found) {
        dc.removeListener('output', seen);
        resolve(found[0].trim());
      }
    };
    dc.on('output', seen);
  });
}

(async () => {
  const dc = new DebugClient(scorpion, contribution.args[0], contribution.type, {}, true);
  dc.defaultTimeout = 30000;
  await dc.start();
  try {
    const initialized = dc.waitForEvent('initialized');
    await dc.initializeRequest({ adapterID: 'scorpion', linesStartAt1: true, columnsStartAt1: true, pathFormat: 'path' });
    await initialized;
    await dc.launchRequest(launch);
    const entry = dc.assertStoppedLocation('entry', {});
    await dc.configurationDoneRequest();
    await entry;
    step('launched, stopped on entry', 'initialize launch configurationDone');

    // One and two, at $0B00; the question, and the robot's answer.
    await dc.send('writeMemory', { memoryReference: '0x0B00', data: Buffer.from([1, 2]).toString('base64') });
    await dc.evaluateRequest({ expression: '/9K0B000002', context: 'repl' });
    const wrong = answer(dc);
    await dc.continueRequest({ threadId: 1 });
    const said = await wrong;
    assert.equal(said, 'K0203', 'the planted bug: one and two make $0203');
    step(`the robot answers ${said}`, 'writeMemory evaluate continue');

    // Stop at the branch only when the carry is clear, and ask again.
    const set = await dc.setBreakpointsRequest({ source: { path: source }, breakpoints: [{ line: branch, condition: 'C == 0' }] });
    assert.equal(set.body.breakpoints[0].verified, true);
    const hit = dc.assertStoppedLocation('breakpoint', { path: source, line: branch });
    await dc.evaluateRequest({ expression: '/9K0B000002', context: 'repl' });
    const stopped = (await hit).body.stackFrames[0];
    const flags = await dc.variablesRequest({ variablesReference: 2 });
    assert.equal(flags.body.variables.find((v) => v.name === 'C').value, '0');
    step(`stopped at checksum.s:${stopped.line} with the carry clear`, 'setBreakpoints(condition) evaluate stackTrace variables');

    // One step: the branch falls through to `inc sum+1`.
    const fell = dc.assertStoppedLocation('step', { path: source, line: branch + 1 });
    await dc.stepInRequest({ threadId: 1 });
    await fell;
    step(`a step goes on to checksum.s:${branch + 1}: ${lines[branch].trim()}`, 'stepIn stackTrace');

    // Back one instruction, and mend the opcode: BCC is $90.
    const back = dc.assertStoppedLocation('step', { path: source, line: branch });
    await dc.stepBackRequest({ threadId: 1 });
    const at = (await back).body.stackFrames[0].instructionPointerReference;
    await dc.send('writeMemory', { memoryReference: at, data: Buffer.from([0x90]).toString('base64') });
    const mended = await dc.send('disassemble', { memoryReference: at, instructionCount: 2 });
    const shown = mended.body.instructions[0].instruction;
    assert.ok(shown.startsWith('BCC @carried'), shown);
    step(`back at ${at}, mended: ${shown}`, 'stepBack writeMemory disassemble');

    // On without the breakpoint: the question under way is answered right.
    await dc.setBreakpointsRequest({ source: { path: source }, breakpoints: [] });
    const right = answer(dc);
    await dc.continueRequest({ threadId: 1 });
    const fixed = await right;
    assert.equal(fixed, 'K0003');
    step(`the robot answers ${fixed}`, 'setBreakpoints continue');
    await dc.disconnectRequest({});
    step('disconnected', 'disconnect');
  } finally {
    dc.stopAdapter();
  }
})().catch((e) => {
  console.error(e.stack || String(e));
  process.exit(1);
});
