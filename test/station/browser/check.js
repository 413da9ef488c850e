// The station's page in a real browser (Debian's chromium, headless, driven by puppeteer-core):
// waits for what the C++ test says the page must show, clicks a goal, takes a screenshot, and
// writes what it saw as JSON for the test to judge (test/station/browser_test.cpp). It judges
// nothing itself: a timeout only ends the wait, and the test then finds the values wrong.
//
//   node check.js --url URL [--size 1280x800] --out RESULT.json --screenshot PNG --cells N --vehicle x,y,z
//                 --processes a,b --goal x,y,z --refused-goal x,y,z [--playback-length S] [--chromium PATH]
// Also --watch S [--until-plan 1 --after A]: instead, stay connected S seconds (or until a plan
// with a path shows, then A seconds more) and report the bytes received per kind.
// Also --fps N: instead, load N synthetic cells through the page's map path and measure the
// frame rate for 5 s (the performance figure; station/README.md).
'use strict';
const fs = require('fs');
const puppeteer = require('puppeteer-core');

function args() {
  const a = {};
  const argv = process.argv.slice(2);
  for (let i = 0; i < argv.length; i += 2) a[argv[i].replace(/^--/, '')] = argv[i + 1];
  return a;
}
const triple = (s) => s.split(',').map(Number);
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

async function waitUntil(page, fn, arg, timeoutMs) {
  try {
    await page.waitForFunction(fn, { timeout: timeoutMs, polling: 100 }, arg);
    return true;
  } catch (e) {
    return false;
  }
}

// How much of the canvas is not the background, and how many colours it holds (the page
// renders a frame and reads it back: station.canvasStats).
async function canvasContent(page) {
  return page.evaluate(() => window.station.canvasStats());
}

async function measureFps(page, cells) {
  await page.evaluate((n) => {
    // A room as OctoMap sees one, surfaces only: half the cells a square floor, half four walls
    // 2.5 m high around it, 5 cm cells; one reset map message (station/wire.h).
    const buf = new ArrayBuffer(16 + 16 * n);
    const dv = new DataView(buf);
    dv.setUint8(0, 1); dv.setUint8(1, 1);
    dv.setUint32(4, n, true); dv.setUint32(8, 0, true); dv.setUint32(12, n, true);
    const f = new Float32Array(buf, 16, 4 * n);
    const e = 0.05, floor = Math.floor(n / 2), side = Math.ceil(Math.sqrt(floor)), half = side * e / 2;
    for (let i = 0; i < floor; ++i) f.set([-half + e * (i % side) + e / 2, -half + e * Math.floor(i / side) + e / 2, e / 2, e], 4 * i);
    const perWall = Math.ceil((n - floor) / 4), layers = 50, along = Math.ceil(perWall / layers);
    for (let i = floor; i < n; ++i) {
      const k = i - floor, wall = Math.floor(k / perWall), j = k % perWall;
      const s = -half + e * (j % along) * (2 * half / (along * e)) + e / 2, z = e * Math.floor(j / along) + e / 2 + e;
      const at = [[s, -half - e / 2], [s, half + e / 2], [-half - e / 2, s], [half + e / 2, s]][wall];
      f.set([at[0], at[1], z, e], 4 * i);
    }
    window.station.applyMapMessage(buf);
    window.station.lookAt(0, 0, 0.5, -9, -11, 9);
  }, cells);
  await sleep(1000);  // the first frames upload the buffer
  const f0 = await page.evaluate(() => window.station.frames());
  const t0 = Date.now();
  await sleep(5000);
  const f1 = await page.evaluate(() => window.station.frames());
  return { cells: await page.evaluate(() => window.station.cellCount()), drawn: await page.evaluate(() => window.station.drawn()),
           fps: (f1 - f0) / ((Date.now() - t0) / 1000) };
}

(async () => {
  const a = args();
  const browser = await puppeteer.launch({
    executablePath: a.chromium || '/usr/bin/chromium',
    headless: true,
    // Root in a container has no sandbox to give; WebGL on the CPU (SwiftShader).
    args: ['--no-sandbox', '--disable-dev-shm-usage', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
           '--window-size=1280,800'],
  });
  const result = { console: [] };
  try {
    const page = await browser.newPage();
    const [width, height] = (a.size || '1280x800').split('x').map(Number);
    await page.setViewport({ width, height });
    page.on('console', (m) => result.console.push(m.type() + ': ' + m.text()));
    page.on('pageerror', (e) => result.console.push('pageerror: ' + e.message));
    await page.goto(a.url, { waitUntil: 'load', timeout: 15000 });
    result.webgl = await page.evaluate(() => !!document.querySelector('#view canvas').getContext('webgl'));
    if (a.watch) {
      // Stay connected for --watch seconds (with --until-plan: until a plan with a path is
      // shown, at most that long, then --after seconds more) and say what crossed the socket.
      if (a['until-plan']) {
        result.plan_shown = await waitUntil(page, () => {
          const p = window.station.plan();
          return p && p.status_name === 'OK';
        }, null, 1000 * Number(a.watch));
        await sleep(1000 * Number(a.after || 0));
      } else {
        await sleep(1000 * Number(a.watch));
      }
      result.received = await page.evaluate(() => window.station.received());
      result.cells = await page.evaluate(() => window.station.cellCount());
      result.map_info = await page.evaluate(() => window.station.mapInfo());
      if (a.screenshot) await page.screenshot({ path: a.screenshot });
      return;
    }
    if (a.fps) {
      Object.assign(result, await measureFps(page, Number(a.fps)));
      if (a.screenshot) await page.screenshot({ path: a.screenshot });
      return;
    }
    const cells = Number(a.cells);
    result.cells_reached = await waitUntil(page, (n) => window.station.cellCount() === n, cells, 20000);
    result.cells = await page.evaluate(() => window.station.cellCount());
    const v = triple(a.vehicle);
    result.vehicle_reached = await waitUntil(page, (p) => {
      const q = window.station.vehiclePosition();
      return q && Math.hypot(q[0] - p[0], q[1] - p[1], q[2] - p[2]) < 1e-6;
    }, v, 10000);
    result.vehicle = await page.evaluate(() => window.station.vehiclePosition());
    const names = a.processes.split(',');
    result.processes_reached = await waitUntil(page, (n) => n.every((x) => window.station.healthNames().includes(x)), names, 10000);
    result.health_names = await page.evaluate(() => window.station.healthNames());
    await waitUntil(page, () => document.getElementById('depth').naturalWidth > 0, null, 5000);
    result.images = await page.evaluate(() => ['colour', 'depth'].map((id) => {
      const img = document.getElementById(id);
      return [img.naturalWidth, img.naturalHeight];
    }));
    result.health_rows = await page.evaluate(() => document.querySelectorAll('#health tbody tr').length);

    // A goal outside the map, typed: refused in the page.
    const typeGoal = async (g) => {
      for (const [id, value] of [['gx', g[0]], ['gy', g[1]], ['gz', g[2]], ['gyaw', 0]]) {
        await page.$eval('#' + id, (el, val) => { el.value = String(val); }, value);
      }
    };
    let before = await page.evaluate(() => window.station.notices());
    await typeGoal(triple(a['refused-goal']));
    await page.click('#send');
    await waitUntil(page, (n) => window.station.notices() > n, before, 5000);
    result.refused_notice = await page.evaluate(() => window.station.lastNotice());

    // A click on the map at the goal's place, at the goal's height.
    const g = triple(a.goal);
    await typeGoal(g);
    const at = await page.evaluate((p) => window.station.worldToClient(p[0], p[1], p[2]), g);
    before = await page.evaluate(() => window.station.notices());
    await page.mouse.click(at.x, at.y);
    await waitUntil(page, (n) => window.station.notices() > n, before, 5000);
    result.click = at;
    result.click_notice = await page.evaluate(() => window.station.lastNotice());
    result.goal_fields = await page.evaluate(() => ['gx', 'gy', 'gz'].map((id) => Number(document.getElementById(id).value)));
    // A replay's transport bar (the test published a PLAYBACK_STATUS): pause the replay.
    if (a['playback-length']) {
      result.playback_shown = await waitUntil(page, () => !document.getElementById('playback').hidden, null, 10000);
      result.playback = await page.evaluate(() => window.station.playback());
      before = await page.evaluate(() => window.station.notices());
      await page.click('#playpause');
      await waitUntil(page, (n) => window.station.notices() > n, before, 5000);
      result.pause_notice = await page.evaluate(() => window.station.lastNotice());
    }
    await sleep(300);  // a frame with the vehicle and the map drawn
    result.canvas = await canvasContent(page);
    if (a.screenshot) await page.screenshot({ path: a.screenshot });
  } catch (e) {
    result.error = String(e && e.stack || e);
  } finally {
    await browser.close();
    fs.writeFileSync(a.out, JSON.stringify(result, null, 1));
  }
})();
