// Debian's Chromium, headless, as matbake's browser tests start it (render.mjs, check_page.mjs).
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import puppeteer from 'puppeteer-core';

// { browser, userDataDir }, or { why } when Chromium is missing or does not start (the caller exits 77).
export async function launch() {
  const executablePath = process.env.CHROMIUM || '/usr/bin/chromium';
  if (!fs.existsSync(executablePath)) return { why: `no Chromium at ${executablePath} (bash scripts/install-runtime.sh)` };
  const userDataDir = fs.mkdtempSync(path.join(os.tmpdir(), 'matbake-chromium-'));
  try {
    const browser = await puppeteer.launch({
      executablePath, userDataDir, headless: true, timeout: 30000,
      // WebGL on the CPU (SwiftShader through ANGLE); no network beyond 127.0.0.1.
      args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--disable-quic',
        '--no-first-run', '--disable-background-networking', '--disable-component-update', '--disable-sync'],
    });
    return { browser, userDataDir };
  } catch (error) {
    fs.rmSync(userDataDir, { recursive: true, force: true });
    return { why: `Chromium at ${executablePath} did not start: ${String(error.message).split('\n')[0]}` };
  }
}

export async function close(started) {
  await started.browser.close();
  fs.rmSync(started.userDataDir, { recursive: true, force: true });
}

// Every console warning and error, page error, failed request and HTTP error into `messages`.
export function watchConsole(page, messages) {
  page.on('console', (m) => { if (m.type() === 'warn' || m.type() === 'error') messages.push(`${m.type()}: ${m.text()}`); });
  page.on('pageerror', (e) => messages.push(`pageerror: ${e.message}`));
  page.on('requestfailed', (r) => messages.push(`requestfailed: ${r.url()}`));
  page.on('response', (r) => { if (r.status() >= 400) messages.push(`http ${r.status()}: ${r.url()}`); });
}

// Kills Chromium and exits 1 when `seconds` pass; returns the timer to clear.
export function deadline(started, seconds, name) {
  return setTimeout(() => {
    console.error(`${name}: no result within ${seconds} s`);
    started.browser.process()?.kill('SIGKILL');
    process.exit(1);
  }, seconds * 1000);
}
