// Headless Chromium for the editor's browser tests, started as STACK.md says: the system's
// Chromium ($CHROMIUM or /usr/bin/chromium), no sandbox, no GPU, no background networking (it
// keeps trying hosts this machine cannot reach), sound allowed without a gesture. Playwright
// gives every launch a fresh temporary profile (the --user-data-dir of STACK.md).
import { chromium } from 'playwright-core';

export function launch() {
  return chromium.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    headless: true,
    args: [
      '--headless', '--no-sandbox', '--disable-gpu', '--disable-background-networking',
      '--disable-component-update', '--no-first-run', '--autoplay-policy=no-user-gesture-required',
    ],
  });
}
