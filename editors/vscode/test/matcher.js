// Runs the extension's `$scorpion` problem matcher (its regular expressions
// read from package.json) over a command's output the way VS Code applies
// a multi-line matcher: pattern k on the k-th of consecutive lines, each
// field taken from the group its pattern names (the first pattern to give
// a field a value gives it), the severity read as VS Code reads it
// (`Error`/`Warning`, any case; otherwise the matcher's own). Prints the
// problems found as a JSON array: [{file, line, column, severity, code, message}].
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

const severityOf = (value) => {
  const known = ['error', 'warning', 'info'];
  const lower = (value || '').toLowerCase();
  if (known.includes(lower)) return lower;
  if (lower === 'warn') return 'warning';
  return matcher.severity || 'error';
};

const lines = fs.readFileSync(process.argv[2], 'utf8').split(/\r?\n/);
const problems = [];
for (let start = 0; start + patterns.length <= lines.length; start++) {
  const problem = {};
  const matched = patterns.every((pattern, k) => {
    const m = pattern.regexp.exec(lines[start + k]);
    if (!m) return false;
    for (const field of ['file', 'line', 'column', 'severity', 'code', 'message']) {
      if (typeof pattern[field] === 'number' && problem[field] === undefined && m[pattern[field]] !== undefined) {
        problem[field] = m[pattern[field]];
      }
    }
    return true;
  });
  if (matched) {
    problem.line = Number(problem.line);
    problem.column = Number(problem.column);
    problem.severity = severityOf(problem.severity);
    problems.push(problem);
  }
}
console.log(JSON.stringify(problems));
