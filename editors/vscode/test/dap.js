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
