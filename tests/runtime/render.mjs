// Renders glTF files in three.js (npm, pinned in package-lock.json) inside Debian's Chromium, headless
// with SwiftShader, served from 127.0.0.1 only; for matbake's runtime test and its delivery bench.
//
//   node render.mjs --out DIR [--size 256] NAME=FILE.glb|.gltf ...
//
// Writes DIR/NAME-{fit,near,far}.png and DIR/report.json: per NAME, what three.js made of each texture
// (slot, colour space, levels, filter) and every console warning or error the page raised.
// Exit 77 when Chromium cannot be started (the caller skips and says why), 1 on any other failure.
// The whole run is bounded by --timeout seconds (default 120); Chromium dies with this process.
import http from 'node:http';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { close, deadline, launch, watchConsole } from './chromium.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const threeRoot = path.join(here, 'node_modules', 'three');

const TYPES = {
  '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript', '.wasm': 'application/wasm',
  '.json': 'application/json', '.png': 'image/png', '.jpg': 'image/jpeg', '.jpeg': 'image/jpeg',
  '.webp': 'image/webp', '.ktx2': 'image/ktx2', '.glb': 'model/gltf-binary', '.gltf': 'model/gltf+json',
  '.bin': 'application/octet-stream',
};

function parseArguments(argv) {
  const options = { out: null, size: 256, timeout: 120, models: [] };
  for (let i = 0; i < argv.length; ++i) {
    const a = argv[i];
    if (a === '--out') options.out = argv[++i];
    else if (a === '--size') options.size = Number(argv[++i]);
    else if (a === '--timeout') options.timeout = Number(argv[++i]);
    else if (/^[A-Za-z0-9_-]+=/.test(a)) {
      const at = a.indexOf('=');
      options.models.push({ name: a.slice(0, at), file: path.resolve(a.slice(at + 1)) });
    } else throw new Error(`render.mjs: unknown argument '${a}'`);
  }
  if (!options.out || options.models.length === 0) throw new Error('render.mjs: usage: --out DIR NAME=FILE ...');
  if (!(options.size >= 16 && options.size <= 2048)) throw new Error('render.mjs: --size must be 16 to 2048');
  return options;
}

// A file under `root`, or null: the path is resolved and must stay inside.
function under(root, relative) {
  const file = path.resolve(root, '.' + path.posix.normalize('/' + decodeURIComponent(relative)));
  return file === root || file.startsWith(root + path.sep) ? file : null;
}

// Serves the page, three.js, and each model's folder at /models/I/ — nothing else.
function serve(models) {
  const server = http.createServer((request, response) => {
    const url = new URL(request.url, 'http://127.0.0.1');
    let file = null;
    if (url.pathname === '/') file = path.join(here, 'page.html');
    else if (url.pathname === '/page.mjs') file = path.join(here, 'page.mjs');
    else if (url.pathname.startsWith('/three/')) file = under(threeRoot, url.pathname.slice(7));
    else {
      const match = /^\/models\/(\d+)\/(.+)$/.exec(url.pathname);
      if (match && Number(match[1]) < models.length) file = under(path.dirname(models[Number(match[1])].file), match[2]);
    }
    if (!file || !fs.existsSync(file) || !fs.statSync(file).isFile()) {
      response.writeHead(404).end();
      return;
    }
    response.writeHead(200, { 'Content-Type': TYPES[path.extname(file).toLowerCase()] || 'application/octet-stream' });
    fs.createReadStream(file).pipe(response);
  });
  return new Promise((resolve) => server.listen(0, '127.0.0.1', () => resolve(server)));
}

function threeVersion() {
  return JSON.parse(fs.readFileSync(path.join(threeRoot, 'package.json'), 'utf8')).version;
}

async function renderAll(browser, server, options) {
  const page = await browser.newPage();
  const messages = [];
  watchConsole(page, messages);
  await page.goto(`http://127.0.0.1:${server.address().port}/`);
  await page.waitForFunction('window.matbakeReady === true', { timeout: 30000 });
  const report = {};
  for (const [i, model] of options.models.entries()) {
    messages.length = 0;
    const url = `/models/${i}/${encodeURIComponent(path.basename(model.file))}`;
    const result = await page.evaluate((u, s) => window.matbakeRender(u, s), url, options.size);
    for (const [view, dataUrl] of Object.entries(result.images)) {
      fs.writeFileSync(path.join(options.out, `${model.name}-${view}.png`), Buffer.from(dataUrl.split(',')[1], 'base64'));
    }
    report[model.name] = { textures: result.textures, console: [...messages] };
  }
  return report;
}

async function main() {
  const options = parseArguments(process.argv.slice(2));
  fs.mkdirSync(options.out, { recursive: true });
  const started = await launch();
  if (!started.browser) {
    console.error(`render.mjs: ${started.why}`);
    process.exit(77);
  }
  const timer = deadline(started, options.timeout, 'render.mjs');
  const server = await serve(options.models);
  try {
    const models = await renderAll(started.browser, server, options);
    const report = { chromium: await started.browser.version(), three: threeVersion(), models };
    fs.writeFileSync(path.join(options.out, 'report.json'), JSON.stringify(report, null, 1) + '\n');
  } finally {
    clearTimeout(timer);
    server.close();
    await close(started);
  }
}

main().catch((error) => {
  console.error(`render.mjs: ${error.message}`);
  process.exit(1);
});
