// Bundles the viewer (src/main.js and three.js) with esbuild and inlines it into
// src/viewer.html: one page template with no external reference, where `primseg view` puts
// its data at <!--PRIMSEG_DATA-->.
//
// Usage: node build.mjs OUTPUT.html
import { build } from 'esbuild';
import { mkdirSync, readFileSync, renameSync, writeFileSync } from 'node:fs';
import { dirname, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const output = resolve(process.argv[2] ?? resolve(here, 'dist/viewer.html'));

const result = await build({
  entryPoints: [resolve(here, 'src/main.js')],
  bundle: true,
  minify: true,
  format: 'iife',
  target: ['es2020'],
  charset: 'ascii', // the page is embedded in C++ as a raw string: keep it 7-bit
  legalComments: 'eof',
  write: false,
  logLevel: 'warning',
});
let script = result.outputFiles[0].text;
// Inside an inline <script>, "</script" would end the element early.
script = script.replace(/<\/script/gi, '<\\/script');

const template = readFileSync(resolve(here, 'src/viewer.html'), 'utf8');
const placeholder = '<script>/*PRIMSEG_BUNDLE*/</script>';
if (!template.includes(placeholder) || !template.includes('<!--PRIMSEG_DATA-->'))
  throw new Error('src/viewer.html lacks its placeholders');
const page = template.replace(placeholder, () => `<script>${script}</script>`);
if (/[^\x00-\x7f]/.test(page)) throw new Error('the page must be ASCII');

mkdirSync(dirname(output), { recursive: true });
writeFileSync(output + '.tmp', page);
renameSync(output + '.tmp', output);
