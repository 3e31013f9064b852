// Builds the gallery page template: web/src/gallery.js bundled with three.js (pinned in
// package-lock.json) into one script with esbuild, then inlined with the stylesheet into
// web/src/gallery.html. The result is a single HTML file that needs no network; `diverse
// gallery` puts a run's data in place of its __DIVERSE_GALLERY_DATA__ data marker.
//
//   node build.mjs [OUT]     (default: dist/gallery-template.html)
//
// Run `npm ci` in this folder first. Without node_modules this prints what to do and exits
// 0, so a C++ build that calls it never fails because of it.
import { existsSync } from 'node:fs';
import { mkdir, readFile, rename, writeFile } from 'node:fs/promises';
import { dirname, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const out = resolve(process.argv[2] ?? resolve(here, 'dist/gallery-template.html'));

for (const dep of ['three', 'esbuild']) {
  if (!existsSync(resolve(here, 'node_modules', dep))) {
    console.warn(`gallery page not built: ${resolve(here, 'node_modules', dep)} is missing; ` +
                 `run \`npm ci\` in ${here}`);
    process.exit(0);
  }
}

const { build } = await import('esbuild');
const result = await build({
  entryPoints: [resolve(here, 'src/gallery.js')],
  bundle: true,
  format: 'iife',
  minify: true,
  target: ['es2020'],
  legalComments: 'eof',  // keeps three.js's MIT licence notice
  write: false,
  logLevel: 'warning',
});
// "</script" inside the inlined script would end the element early.
const script = result.outputFiles[0].text.replace(/<\/script/gi, '<\\/script');
const style = await readFile(resolve(here, 'src/gallery.css'), 'utf8');
let html = await readFile(resolve(here, 'src/gallery.html'), 'utf8');
for (const marker of ['/*__GALLERY_STYLE__*/', '/*__GALLERY_SCRIPT__*/', '__DIVERSE_GALLERY_DATA__']) {
  if (html.split(marker).length !== 2) throw new Error(`src/gallery.html: expected one ${marker}`);
}
html = html.replace('/*__GALLERY_STYLE__*/', () => style).replace('/*__GALLERY_SCRIPT__*/', () => script);
if (html.split('__DIVERSE_GALLERY_DATA__').length !== 2) {
  throw new Error('the bundled script contains the data data marker');
}
await mkdir(dirname(out), { recursive: true });
await writeFile(`${out}.tmp`, html);
await rename(`${out}.tmp`, out);
console.log(`${out} (${(html.length / 1e6).toFixed(2)} MB)`);
