// Packages the extension with vsce (as CI does) into OUT.vsix and checks
// what went in: the manifest as written, every file the manifest points at
// (grammar, language configuration), the README, and none of node_modules
// or test/. Prints the packaged entries.
// Usage: node test/package.js OUT.vsix
'use strict';
const assert = require('assert');
const fs = require('fs');
const path = require('path');
const { execFileSync } = require('child_process');
const yauzl = require('yauzl');

const out = process.argv[2];
if (!out) throw new Error('usage: node test/package.js OUT.vsix');
const root = path.join(__dirname, '..');
const vsce = path.join(root, 'node_modules', '@vscode', 'vsce', 'vsce');
execFileSync(process.execPath, [vsce, 'package', '--skip-license', '--out', out], {
  cwd: root,
  stdio: ['ignore', 'inherit', 'inherit'],
});

function entries(file) {
  return new Promise((resolve, reject) => {
    yauzl.open(file, { lazyEntries: true }, (error, zip) => {
      if (error) return reject(error);
      const found = new Map();
      zip.on('entry', (entry) => {
        zip.openReadStream(entry, (e, stream) => {
          if (e) return reject(e);
          const chunks = [];
          stream.on('data', (c) => chunks.push(c));
          stream.on('end', () => {
            found.set(entry.fileName, Buffer.concat(chunks));
            zip.readEntry();
          });
        });
      });
      zip.on('end', () => resolve(found));
      zip.on('error', reject);
      zip.readEntry();
    });
  });
}

(async () => {
  const found = await entries(out);
  const names = [...found.keys()].sort();
  console.log(names.join('\n'));
  const manifest = JSON.parse(fs.readFileSync(path.join(root, 'package.json'), 'utf8'));
  const packaged = JSON.parse(found.get('extension/package.json').toString('utf8'));
  for (const key of ['name', 'publisher', 'version', 'engines', 'contributes']) {
    assert.deepEqual(packaged[key], manifest[key], `the packaged manifest's ${key}`);
  }
  const pointedAt = [
    ...manifest.contributes.grammars.map((g) => g.path),
    ...manifest.contributes.languages.map((l) => l.configuration),
  ];
  for (const file of pointedAt) {
    const entry = path.posix.join('extension', path.posix.normalize(file));
    assert.ok(found.has(entry), `${entry} is in the package`);
    assert.deepEqual(found.get(entry), fs.readFileSync(path.join(root, file)), `${entry} as written`);
  }
  assert.ok(names.some((n) => n.toLowerCase() === 'extension/readme.md'), 'the README is in the package');
  assert.ok(found.has('extension.vsixmanifest'), 'a VSIX manifest');
  for (const name of names) {
    assert.ok(!name.startsWith('extension/node_modules/') && !name.startsWith('extension/test/'), `${name} left out`);
  }
})().catch((e) => {
  console.error(e.stack || String(e));
  process.exit(1);
});
