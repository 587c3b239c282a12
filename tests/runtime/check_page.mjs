// Opens an HTML page (a file: matbake's report page) in Debian's Chromium, headless, and says what
// a reader would see: every console warning or error and failed request, each image with its
// natural size (0: it did not load), the page's section ids and headings; optionally a screenshot.
//
//   node check_page.mjs PAGE.html --out RESULT.json [--screenshot FILE.png] [--width 1200] [--timeout 60]
//
// Writes the result as JSON. Exit 77 when Chromium cannot be started (the caller skips and says
// why), 1 on any other failure. Chromium dies with this process.
import fs from 'node:fs';
import path from 'node:path';
import { pathToFileURL } from 'node:url';
import { close, deadline, launch, watchConsole } from './chromium.mjs';

function parseArguments(argv) {
  const options = { page: null, out: null, screenshot: null, width: 1200, timeout: 60 };
  for (let i = 0; i < argv.length; ++i) {
    const a = argv[i];
    if (a === '--out') options.out = argv[++i];
    else if (a === '--screenshot') options.screenshot = argv[++i];
    else if (a === '--width') options.width = Number(argv[++i]);
    else if (a === '--timeout') options.timeout = Number(argv[++i]);
    else if (!options.page) options.page = path.resolve(a);
    else throw new Error(`check_page.mjs: unknown argument '${a}'`);
  }
  if (!options.page || !options.out) throw new Error('check_page.mjs: usage: PAGE.html --out RESULT.json [--screenshot FILE.png]');
  return options;
}

async function main() {
  const options = parseArguments(process.argv.slice(2));
  const started = await launch();
  if (!started.browser) {
    console.error(`check_page.mjs: ${started.why}`);
    process.exit(77);
  }
  const timer = deadline(started, options.timeout, 'check_page.mjs');
  try {
    const page = await started.browser.newPage();
    await page.setViewport({ width: options.width, height: 900 });
    const console = [];
    watchConsole(page, console);
    await page.goto(pathToFileURL(options.page).href, { waitUntil: 'load' });
    const seen = await page.evaluate(() => ({
      images: [...document.images].map((i) => ({ src: i.getAttribute('src'), naturalWidth: i.naturalWidth, naturalHeight: i.naturalHeight })),
      sections: [...document.querySelectorAll('section')].map((s) => s.id),
      headings: [...document.querySelectorAll('h1, h2, h3, h4')].map((h) => h.textContent),
      scripts: document.scripts.length,
    }));
    if (options.screenshot) fs.writeFileSync(options.screenshot, await page.screenshot({ fullPage: true }));
    fs.writeFileSync(options.out, JSON.stringify({ console, ...seen }, null, 1) + '\n');
  } finally {
    clearTimeout(timer);
    await close(started);
  }
}

main().catch((error) => {
  console.error(`check_page.mjs: ${error.message}`);
  process.exit(1);
});
