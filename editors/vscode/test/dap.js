// A debugging session through the extension's own debugger contribution,
// driven by VS Code's DAP test client (@vscode/debugadapter-testsupport):
// the adapter is started exactly as package.json tells VS Code to (its
// `program`, the `scorpion` binary given here, with its `args`), launched
// with the contribution's first configuration snippet on the ADC example.
// Usage: node test/dap.js SCORPION_BINARY EXAMPLE_DIR [ADAPTER_JSON]
// With ADAPTER_JSON ({"args": [...], "launch": {...}}, another editor's
// adapter definition and launch configuration, `${workspaceFolder}` left
// as written), the session runs through that instead of package.json.
'use strict';
const assert = require('assert');
const fs = require('fs');
const path = require('path');
const { DebugClient } = require('@vscode/debugadapter-testsupport');

const [scorpion, example, other] = process.argv.slice(2);
if (!scorpion || !example) throw new Error('usage: node test/dap.js SCORPION_BINARY EXAMPLE_DIR');

const manifest = JSON.parse(fs.readFileSync(path.join(__dirname, '..', 'package.json'), 'utf8'));
const debuggerContribution = manifest.contributes.debuggers.find((d) => d.type === 'scorpion');
assert.ok(debuggerContribution, 'package.json contributes a `scorpion` debugger');
assert.equal(debuggerContribution.program, 'scorpion', 'VS Code runs `scorpion` from PATH');
// DebugClient passes one argument; VS Code passes them all. One is what we have.
assert.deepEqual(debuggerContribution.args, ['dap']);

// The launch configuration a user gets from the first snippet, with
// `${workspaceFolder}` resolved as VS Code would.
function fromSnippet(snippet, workspaceFolder) {
  const text = JSON.stringify(snippet.body)
    .replace(/\^\\"\\\\\$\{workspaceFolder\}\\"/g, JSON.stringify(workspaceFolder).slice(1, -1))
    .replace(/\$\{\d+:([^}]*)\}/g, '$1');
  return JSON.parse(text);
}
const otherEditor = other ? JSON.parse(fs.readFileSync(other, 'utf8')) : null;
const adapterArgs = otherEditor ? otherEditor.args : debuggerContribution.args;
assert.deepEqual(adapterArgs, ['dap'], 'the adapter is `scorpion dap`');
const launch = otherEditor
  ? JSON.parse(JSON.stringify(otherEditor.launch).split('${workspaceFolder}').join(example))
  : fromSnippet(debuggerContribution.configurationSnippets[0], example);
assert.equal(launch.type, debuggerContribution.type);
assert.equal(launch.request, 'launch');
assert.equal(launch.program, example, 'the snippet launches the workspace folder');
for (const key of Object.keys(launch).filter((k) => !['type', 'request', 'name'].includes(k))) {
  assert.ok(key in debuggerContribution.configurationAttributes.launch.properties, `${key} is a declared attribute`);
}
// The ADC example answers `/2A1`; the launch types it to the robot.
if (!otherEditor) launch.commands = ['/2A1'];
assert.deepEqual(launch.commands, ['/2A1'], 'the launch types /2A1 to the robot');

const source = path.join(example, 'adc.s');
const lines = fs.readFileSync(source, 'utf8').split('\n');
// The lines are found by their text, so an edit of the example moves them.
const lineOf = (text) => {
  const index = lines.findIndex((l) => l.trim().startsWith(text));
  assert.ok(index >= 0, `adc.s has a line starting ${text}`);
  return index + 1;
};
const sec = lineOf('sec');

const log = (what) => console.log(`dap: ${what}`);

(async () => {
  const dc = new DebugClient(scorpion, adapterArgs[0], debuggerContribution.type, {}, true);
  dc.defaultTimeout = 30000;
  await dc.start();
  try {
    const initialized = dc.waitForEvent('initialized');
    const init = await dc.initializeRequest({ adapterID: 'scorpion', linesStartAt1: true, columnsStartAt1: true, pathFormat: 'path' });
    assert.ok(init.success);
    await initialized;
    log('initialized');
    const response = await dc.launchRequest(launch);
    assert.ok(response.success, JSON.stringify(response));
    log(`launched ${launch.program}`);

    const set = await dc.setBreakpointsRequest({ source: { path: source }, breakpoints: [{ line: sec }] });
    assert.equal(set.body.breakpoints.length, 1);
    assert.equal(set.body.breakpoints[0].verified, true, JSON.stringify(set.body));
    log(`breakpoint at adc.s:${sec} verified`);

    if (launch.stopOnEntry) {
      const entry = dc.assertStoppedLocation('entry', {});
      await dc.configurationDoneRequest();
      await entry;
      log('stopped on entry');
    } else {
      await dc.configurationDoneRequest();
    }

    const hit = dc.assertStoppedLocation('breakpoint', { path: source, line: sec });
    if (launch.stopOnEntry) await dc.continueRequest({ threadId: 1 });
    const trace = await hit;
    const frame = trace.body.stackFrames[0];
    log(`hit ${path.basename(frame.source.path)}:${frame.line} in ${frame.name}`);

    const scopes = await dc.scopesRequest({ frameId: frame.id });
    const registers = scopes.body.scopes.find((s) => s.name === 'Registers');
    assert.ok(registers, JSON.stringify(scopes.body));
    const variables = await dc.variablesRequest({ variablesReference: registers.variablesReference });
    const value = (name) => {
      const v = variables.body.variables.find((x) => x.name === name);
      assert.ok(v, `a register ${name} in ${JSON.stringify(variables.body)}`);
      return v.value;
    };
    for (const name of ['A', 'X', 'Y', 'PC']) value(name);
    // /2A1: the channel digit '1' ($31) was loaded into A just before `sec`.
    assert.equal(value('A'), '$31');
    log(`registers: ${variables.body.variables.map((v) => `${v.name}=${v.value}`).join(' ')}`);

    const stepped = dc.assertStoppedLocation('step', { path: source, line: sec + 1 });
    await dc.nextRequest({ threadId: 1 });
    await stepped;
    log(`stepped to adc.s:${sec + 1}`);

    // Issue 25, point 2: each request an assembly debugger answers, as VS
    // Code sends them from its views (breakpoints, variables, memory,
    // disassembly, exceptions, loaded scripts, the restart button).
    for (const capability of [
      'supportsConditionalBreakpoints', 'supportsHitConditionalBreakpoints', 'supportsLogPoints',
      'supportsFunctionBreakpoints', 'supportsDataBreakpoints', 'supportsInstructionBreakpoints',
      'supportsDisassembleRequest', 'supportsSetVariable', 'supportsWriteMemoryRequest',
      'supportsReadMemoryRequest', 'supportsRestartRequest', 'supportsExceptionInfoRequest',
      'supportsLoadedSourcesRequest',
    ]) assert.equal(init.body[capability], true, capability);
    assert.deepEqual(init.body.exceptionBreakpointFilters.map((f) => f.filter), ['jam', 'brk', 'card']);

    const loaded = await dc.send('loadedSources', {});
    assert.ok(loaded.body.sources.some((s) => s.path === source), JSON.stringify(loaded.body));
    log('loadedSources: adc.s');

    const here = (await dc.stackTraceRequest({ threadId: 1 })).body.stackFrames[0];
    const listing = await dc.send('disassemble', {
      memoryReference: here.instructionPointerReference, instructionOffset: -2, instructionCount: 6,
    });
    const at = listing.body.instructions[2];
    assert.equal(at.address, here.instructionPointerReference);
    assert.equal(at.line, sec + 1);
    log(`disassemble: ${at.address} ${at.instruction}`);

    // A = $32: the channel digit '2', so the robot reads channel 2.
    const setA = await dc.send('setVariable', { variablesReference: registers.variablesReference, name: 'A', value: '$32' });
    assert.equal(setA.body.value, '$32');
    log('setVariable A = $32');

    await dc.send('writeMemory', { memoryReference: '0x0300', data: 'ASNF' });
    const read = await dc.send('readMemory', { memoryReference: '0x0300', count: 3 });
    assert.equal(read.body.data, 'ASNF');
    log('writeMemory and readMemory at $0300');

    const info = await dc.send('dataBreakpointInfo', { name: 'ADC_CONTROL' });
    assert.equal(info.body.dataId, '0x9000');
    await dc.send('setDataBreakpoints', { breakpoints: [{ dataId: info.body.dataId, accessType: 'write' }] });
    const watched = dc.waitForEvent('stopped');
    await dc.continueRequest({ threadId: 1 });
    const wrote = (await watched).body;
    assert.equal(wrote.reason, 'data breakpoint');
    assert.ok(wrote.description.startsWith('wrote $82 to $9000'), wrote.description);
    log(`data breakpoint: ${wrote.description}`);
    await dc.send('setDataBreakpoints', { breakpoints: [] });

    const fn = await dc.send('setFunctionBreakpoints', { breakpoints: [{ name: 'PUTHEX' }] });
    assert.equal(fn.body.breakpoints[0].verified, true);
    const called = dc.waitForEvent('stopped');
    await dc.continueRequest({ threadId: 1 });
    assert.equal((await called).body.reason, 'function breakpoint');
    log('function breakpoint at PUTHEX');
    await dc.send('setFunctionBreakpoints', { breakpoints: [] });

    // /2A3 stops at `sec` only when A holds its digit; the wait loop logs.
    const wait = lineOf('@wait:');
    await dc.setBreakpointsRequest({ source: { path: source }, breakpoints: [
      { line: sec, condition: 'A == $33', hitCondition: '1' },
      { line: wait, logMessage: 'status {[$9001]}' },
    ] });
    const conditional = dc.waitForEvent('stopped');
    await dc.evaluateRequest({ expression: '/2A3', context: 'repl' });
    await dc.continueRequest({ threadId: 1 });
    assert.equal((await conditional).body.reason, 'breakpoint');
    const third = (await dc.stackTraceRequest({ threadId: 1 })).body.stackFrames[0];
    assert.equal(third.line, sec);
    log(`conditional breakpoint at adc.s:${third.line}`);

    const call = (await dc.send('disassemble', { memoryReference: third.instructionPointerReference, instructionCount: 20 }))
      .body.instructions.find((i) => i.instruction.startsWith('JSR'));
    await dc.send('setInstructionBreakpoints', { breakpoints: [{ instructionReference: call.address }] });
    // The log point's lines, among the robot's own output.
    const logged = new Promise((resolve) => {
      const seen = (event) => {
        if (event.body.category === 'console' && event.body.output.startsWith('status $')) {
          dc.removeListener('output', seen);
          resolve(event);
        }
      };
      dc.on('output', seen);
    });
    const instruction = dc.waitForEvent('stopped');
    await dc.continueRequest({ threadId: 1 });
    await logged;
    assert.equal((await instruction).body.reason, 'instruction breakpoint');
    log(`log point and instruction breakpoint at ${call.address}`);

    await dc.setExceptionBreakpointsRequest({ filters: ['brk'] });
    await dc.send('writeMemory', { memoryReference: call.address, data: 'AA==' });
    const brk = dc.waitForEvent('stopped');
    await dc.continueRequest({ threadId: 1 });
    assert.equal((await brk).body.reason, 'exception');
    const exception = await dc.send('exceptionInfo', { threadId: 1 });
    assert.equal(exception.body.exceptionId, 'brk');
    log(`exception: ${exception.body.description}`);

    // A new robot: the BRK planted is gone, the breakpoints stay, and the
    // launch's /2A1 runs again to the instruction breakpoint.
    const restarted = dc.waitForEvent('stopped');
    await dc.send('restart', {});
    if (launch.stopOnEntry) {
      assert.equal((await restarted).body.reason, 'entry');
      const again = dc.waitForEvent('stopped');
      await dc.continueRequest({ threadId: 1 });
      assert.equal((await again).body.reason, 'instruction breakpoint');
    } else {
      assert.equal((await restarted).body.reason, 'instruction breakpoint');
    }
    log('restarted');
    await dc.send('setInstructionBreakpoints', { breakpoints: [] });

    await dc.setBreakpointsRequest({ source: { path: source }, breakpoints: [] });
    const ended = new Promise((resolve) => {
      dc.once('terminated', () => resolve('terminated'));
      dc.once('stopped', () => resolve('stopped'));
      setTimeout(() => resolve('running'), 1000);
    });
    const cont = await dc.continueRequest({ threadId: 1 });
    assert.ok(cont.success);
    log(`continued (${await ended})`);

    const disconnect = await dc.disconnectRequest({});
    assert.ok(disconnect.success);
    log('disconnected');
  } finally {
    dc.stopAdapter();
  }
})().catch((e) => {
  console.error(e.stack || String(e));
  process.exit(1);
});
