// Runs the extension's `$scorpion` problem matcher (its regular expressions
// read from package.json) over a command's output the way VS Code applies
// a multi-line matcher: pattern k on the k-th of consecutive lines, the
// fields taken from the groups the pattern names. Prints the problems found
// as a JSON array: [{file, line, column, severity, message}].
// Usage: node test/matcher.js OUTPUT_FILE
'use strict';
const fs = require('fs');
const path = require('path');

const manifest = JSON.parse(fs.readFileSync(path.join(__dirname, '..', 'package.json'), 'utf8'));
const matcher = manifest.contributes.problemMatchers.find((m) => m.name === 'scorpion');
if (!matcher) throw new Error('package.json contributes no `scorpion` problem matcher');
const patterns = (Array.isArray(matcher.pattern) ? matcher.pattern : [matcher.pattern]).map((p) => ({
  ...p,
  regexp: new RegExp(p.regexp),
}));

const lines = fs.readFileSync(process.argv[2], 'utf8').split(/\r?\n/);
const problems = [];
for (let start = 0; start + patterns.length <= lines.length; start++) {
  const problem = { severity: matcher.severity };
  const matched = patterns.every((pattern, k) => {
    const m = pattern.regexp.exec(lines[start + k]);
    if (!m) return false;
    for (const field of ['file', 'line', 'column', 'severity', 'code', 'message']) {
      if (typeof pattern[field] === 'number') problem[field] = m[pattern[field]];
    }
    return true;
  });
  if (matched) {
    problem.line = Number(problem.line);
    problem.column = Number(problem.column);
    problems.push(problem);
  }
}
console.log(JSON.stringify(problems));
