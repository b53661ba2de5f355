// Drives the live view of `scorpion sim --view` in the system's chromium,
// headless, with playwright-core (no browser download): loads the page,
// sends /2A1 from the console and sees the answer, then drives both
// motors and sees the drawn robot move. Prints a line per step; exits 1
// with what it saw on any failure.
//
// node view.js URL CHROMIUM [SCREENSHOT.png]
"use strict";

const { chromium } = require("playwright-core");

const [url, executablePath, screenshot] = process.argv.slice(2);
// Each wait, in wall time: a loaded CI machine ran the robot to the post
// in more than 30 s once (the whole test is bounded by the Rust side's 180 s).
const PATIENCE = 60000;

async function main() {
  const browser = await chromium.launch({
    executablePath,
    headless: true,
    args: ["--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage"],
  });
  try {
    const page = await browser.newPage({ viewport: { width: 1200, height: 800 } });
    const errors = [];
    page.on("pageerror", (error) => errors.push(String(error)));
    page.on("console", (message) => {
      if (message.type() === "error") errors.push(message.text());
    });
    await page.goto(url);
    await page.waitForSelector('#status[data-state="open"]', { timeout: PATIENCE });
    console.log("view: connected");
    await page.waitForSelector("#robot[data-x]", { timeout: PATIENCE });
    const start = Number(await page.getAttribute("#robot", "data-x"));
    console.log(`view: robot drawn at x=${start}`);

    await page.fill("#command", "/2A1");
    await page.press("#command", "Enter");
    await page.waitForFunction(
      () => [...document.querySelectorAll("#console .answer")].length >= 1,
      null,
      { timeout: PATIENCE },
    );
    const sent = await page.textContent("#console .sent");
    const answer = await page.textContent("#console .answer");
    console.log(`view: console ${sent} ${answer}`);

    for (const command of ["/4C+40", "/4D+40"]) {
      await page.fill("#command", command);
      await page.press("#command", "Enter");
    }
    await page.waitForFunction(
      (from) => Number(document.getElementById("robot").dataset.x) > from + 3,
      start,
      { timeout: PATIENCE },
    );
    const moved = Number(await page.getAttribute("#robot", "data-x"));
    const transform = await page.getAttribute("#robot", "transform");
    const trail = await page.getAttribute("#trail", "points");
    console.log(`view: robot moved to x=${moved} (${transform}), trail of ${trail.trim().split(/\s+/).length} points`);
    // The bumpers are named (bit and place), in a list named by its
    // header: the front one (bit 4) open before the bump.
    const front = page
      .getByRole("list", { name: "Bumpers" })
      .getByRole("listitem")
      .filter({ hasText: /^4 front (open|closed)$/ });
    if ((await front.count()) !== 1) throw new Error(`no one bumper named "4 front": ${await page.textContent("#bumpers")}`);
    // The robot meets the post 45 cm ahead: its front bumper drawn closed.
    await page.waitForFunction(
      () => {
        const item = document.querySelector('#bumpers li[data-name="4 front"]');
        return item && item.classList.contains("on") && item.textContent.endsWith("closed");
      },
      null,
      { timeout: PATIENCE },
    );
    const named = (await front.textContent()).trim();
    // Every bumper named with its state; the back ones open. (The robot
    // drives on against the post while this is read: on a loaded machine
    // a front corner closes too, so those two may be either.)
    const all = await page.$$eval("#bumpers li", (items) => items.map((i) => i.textContent.trim()));
    const back = ["0 back open", "1 back-right open", "7 back-left open"];
    if (all.length !== 8 || !all.every((t) => /^[0-7] [a-z-]+ (open|closed)$/.test(t)) || !back.every((t) => all.includes(t)))
      throw new Error(`the bumpers: ${all}`);
    const title = await page.textContent('#robot .bumper[data-bit="4"] title');
    console.log(`view: bumper named "${named}", drawn as "${title}"`);
    for (const [list, name] of [["Trackers", "left"], ["Trackers", "right"], ["Lamps", "tracker lamps"], ["Eyes", "left"], ["Eyes", "right"]]) {
      const item = page.getByRole("list", { name: list }).getByRole("listitem").filter({ hasText: new RegExp(`^${name} (lit|dark|on|off)$`) });
      if ((await item.count()) !== 1) throw new Error(`no ${list} item named "${name}"`);
    }
    console.log("view: trackers, lamps and eyes named");
    // And on the drawn robot: its front arc red.
    await page.waitForFunction(
      () => document.querySelector('#robot .bumper[data-bit="4"]').getAttribute("stroke") === "#c00",
      null,
      { timeout: PATIENCE },
    );
    console.log("view: bumper 4 front closed at the post");
    if (screenshot) await page.screenshot({ path: screenshot });
    if (errors.length) throw new Error(`the page's errors: ${errors.join("; ")}`);
    console.log("view: done");
  } finally {
    await browser.close();
  }
}

main().catch((error) => {
  console.log(`view: failed: ${error && error.stack ? error.stack : error}`);
  process.exit(1);
});
