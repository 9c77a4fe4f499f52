// Debian's chromium driven by playwright-core: never a downloaded browser.
import { chromium } from 'playwright-core';
import { existsSync } from 'node:fs';

export const chromiumPath = process.env.CHROMIUM ?? '/usr/bin/chromium';

export async function launchBrowser() {
  if (!existsSync(chromiumPath))
    throw new Error(`no browser at ${chromiumPath}: install Debian's chromium (scripts/install-deps.sh) or set CHROMIUM`);
  return chromium.launch({
    executablePath: chromiumPath,
    headless: true,
    args: ['--no-sandbox', '--disable-background-networking', '--disable-component-update',
      '--disable-default-apps', '--disable-sync', '--no-first-run', '--metrics-recording-only',
      '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--force-color-profile=srgb'],
  });
}

/** Opens a page from a file, recording console errors and page errors; waits for the viewer. */
export async function openViewer(browser, file, { test = false, width = 1000, height = 700 } = {}) {
  const page = await browser.newPage({ viewport: { width, height } });
  const errors = [];
  page.on('console', (message) => {
    if (message.type() === 'error') errors.push(message.text());
  });
  page.on('pageerror', (error) => errors.push(String(error)));
  const requests = [];
  page.on('request', (request) => {
    if (!request.url().startsWith('file:') && !request.url().startsWith('data:')) requests.push(request.url());
  });
  const start = Date.now();
  await page.goto('file://' + file + (test ? '?test' : ''));
  const loadMs = await page.evaluate(async () => (await window.primseg.ready).loadMs);
  return { page, errors, requests, loadMs, wallMs: Date.now() - start };
}
