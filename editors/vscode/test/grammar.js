// Tokenizes real ca65 sources with the extension's grammar, as VS Code
// does (vscode-textmate over the Oniguruma regular expressions), and checks
// that mnemonics, directives, comments, numbers and labels get their scopes.
// Usage: node test/grammar.js FILE.s...   Prints one line per file; exits 1
// with the offending line on the first wrong or missing scope.
'use strict';
const fs = require('fs');
const path = require('path');
const vsctm = require('vscode-textmate');
const oniguruma = require('vscode-oniguruma');

const root = path.join(__dirname, '..');
const manifest = JSON.parse(fs.readFileSync(path.join(root, 'package.json'), 'utf8'));
const contributed = manifest.contributes.grammars.find((g) => g.language === 'ca65');
const grammarPath = path.join(root, contributed.path);
const grammarJson = JSON.parse(fs.readFileSync(grammarPath, 'utf8'));

const wasm = fs.readFileSync(path.join(path.dirname(require.resolve('vscode-oniguruma')), 'onig.wasm'));
const onigLib = oniguruma.loadWASM(wasm.buffer.slice(wasm.byteOffset, wasm.byteOffset + wasm.byteLength)).then(() => ({
  createOnigScanner: (patterns) => new oniguruma.OnigScanner(patterns),
  createOnigString: (s) => new oniguruma.OnigString(s),
}));

const registry = new vsctm.Registry({
  onigLib,
  loadGrammar: async (scopeName) =>
    scopeName === contributed.scopeName ? vsctm.parseRawGrammar(JSON.stringify(grammarJson), grammarPath) : null,
});

const MNEMONICS = new Set(('adc and asl bcc bcs beq bit bmi bne bpl brk bvc bvs clc cld cli clv cmp cpx cpy dec dex dey ' +
  'eor inc inx iny jmp jsr lda ldx ldy lsr nop ora pha php pla plp rol ror rti rts sbc sec sed sei sta stx sty ' +
  'tax tay tsx txa txs tya alr anc ane arr axs dcp isc jam las lax rla rra sax sha shx shy slo sre tas').split(' '));

function fail(file, n, line, why, tokens) {
  console.error(`${file}:${n}: ${why}\n  ${line}\n  ${JSON.stringify(tokens)}`);
  process.exit(1);
}

(async () => {
  const grammar = await registry.loadGrammar(contributed.scopeName);
  if (!grammar) throw new Error('the grammar did not load');
  const files = process.argv.slice(2);
  if (files.length === 0) throw new Error('no files given');
  for (const file of files) {
    const counts = { mnemonic: 0, directive: 0, comment: 0, number: 0, label: 0 };
    let state = vsctm.INITIAL;
    const lines = fs.readFileSync(file, 'utf8').split(/\r?\n/);
    lines.forEach((line, i) => {
      const result = grammar.tokenizeLine(line, state);
      state = result.ruleStack;
      const tokens = result.tokens.map((t) => ({
        text: line.substring(t.startIndex, t.endIndex),
        scopes: t.scopes.slice(1),
      }));
      const has = (text, scope) => tokens.some((t) => t.text === text && t.scopes.some((s) => s.startsWith(scope)));
      // What ca65 itself would read on this line: the code before a comment
      // (no ';' inside strings or characters in these sources' code).
      const semi = line.search(/;(?=(?:[^"]*"[^"]*")*[^"]*$)/);
      const code = (semi >= 0 ? line.substring(0, semi) : line).replace(/'[^']'?/g, ' ');
      if (semi >= 0) {
        const comment = line.substring(semi);
        if (!tokens.some((t) => t.text === comment && t.scopes.some((s) => s.startsWith('comment.line')))) {
          fail(file, i + 1, line, `the comment is not one comment.line token`, tokens);
        }
        counts.comment++;
      }
      const label = code.match(/^\s*(@?[A-Za-z_]\w*)::?/);
      if (label) {
        if (!has(label[1], 'entity.name.label')) fail(file, i + 1, line, `label ${label[1]} not scoped`, tokens);
        counts.label++;
      }
      const rest = label ? code.substring(label[0].length) : code;
      const word = rest.match(/^\s*([A-Za-z]{3})(?=\s|$)/);
      if (word && MNEMONICS.has(word[1].toLowerCase())) {
        if (!has(word[1], 'keyword.other.mnemonic')) fail(file, i + 1, line, `mnemonic ${word[1]} not scoped`, tokens);
        counts.mnemonic++;
      }
      for (const d of rest.matchAll(/(?<![\w.])\.[A-Za-z_]\w*/g)) {
        if (!has(d[0], 'keyword.')) fail(file, i + 1, line, `directive ${d[0]} not scoped`, tokens);
        counts.directive++;
      }
      for (const n of rest.matchAll(/(?<![\w$%])(\$[0-9A-Fa-f]+|%[01]+)(?!\w)/g)) {
        if (!has(n[1], 'constant.numeric')) fail(file, i + 1, line, `number ${n[1]} not scoped`, tokens);
        counts.number++;
      }
    });
    for (const [what, count] of Object.entries(counts)) {
      if (count === 0 && what !== 'number' && what !== 'label') fail(file, 0, '', `no ${what} seen at all`, []);
    }
    console.log(`${path.basename(file)}: ${lines.length} lines, ` +
      Object.entries(counts).map(([k, v]) => `${v} ${k}s`).join(', '));
  }
})().catch((e) => {
  console.error(e.stack || String(e));
  process.exit(1);
});
