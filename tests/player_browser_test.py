#!/usr/bin/env python3
"""The motion player of report.html in a real browser (headless Chromium through
ChromeDriver and Selenium): runs a short `hairbench compare` with every built-in model on
`shake` and `idle`, opens the page it wrote, and through the page's own controls (the
slider by keyboard, the play button, the speed menu) checks that
  - every canvas draws (not blank) and a frame of all of them draws in at most 33 ms;
  - a moving run's panel changes between frames and a still one's does not;
  - what is drawn is the report's data: the tip of every drawn strand of the reference's
    panel, decoded here from report.json and projected with the stills' camera, lands on
    a drawn pixel, within a pixel of where the page puts it;
  - play advances the frames, faster at 2x than at 1/4x, and pause stops them;
  - the console shows no error.
It saves a screenshot of the first player beside the report.

usage: player_browser_test.py HAIRBENCH CHARTS_PY OUT_DIR   (exit 77 = skipped: no browser)
"""
import base64
import importlib.util
import io
import json
import math
import os
import shutil
import subprocess
import sys
import time

CHROMIUM, CHROMEDRIVER = "/usr/bin/chromium", "/usr/bin/chromedriver"
try:
    from PIL import Image
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys
    from selenium.webdriver.support.ui import Select
except ImportError as e:
    print(f"SKIPPED: {sys.executable} cannot import {e.name}; install Debian's python3-selenium and python3-pil "
          f"(ci/bootstrap does) to test the player in a browser")
    sys.exit(77)
for path in (CHROMIUM, CHROMEDRIVER):
    if not os.access(path, os.X_OK):
        print(f"SKIPPED: no {path}; install Debian's chromium and chromium-driver (ci/bootstrap does)")
        sys.exit(77)

failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAIL:", what)


def load_charts(charts_py):
    spec = importlib.util.spec_from_file_location("charts_under_test", charts_py)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def canvas_image(driver, player, panel):
    url = driver.execute_script(
        "return hbPlayer.players[arguments[0]].panels[arguments[1]].canvas.toDataURL('image/png')", player, panel)
    return Image.open(io.BytesIO(base64.b64decode(url.split(",", 1)[1]))).convert("RGBA")


def drawn(img):
    """Pixels with strands on them: opaque, and neither the head's greys nor the note's red."""
    return sum(1 for r, g, b, a in img.getdata() if a > 0 and not (abs(r - g) < 8 and abs(g - b) < 8))


def differing(a, b):
    return sum(1 for p, q in zip(a.getdata(), b.getdata()) if max(abs(x - y) for x, y in zip(p, q)) > 40)


def slider_to(driver, roots, player, k):
    """Moves a player's slider to recorded frame k with the keyboard, as a reader would."""
    slider = roots[player].find_element(By.CLASS_NAME, "hb-slider")
    slider.send_keys(Keys.HOME)
    slider.send_keys(*([Keys.ARROW_RIGHT] * k))
    return driver.execute_script("return hbPlayer.players[arguments[0]].k", player)


def check_gif(charts_py, out, report):
    """charts.py --animate: one GIF frame per recorded frame, moving, small enough for a
    README; an unknown scenario is a one-line error."""
    run = subprocess.run([sys.executable, charts_py, os.path.join(out, "report.json"), "--animate", "shake"],
                         capture_output=True, text=True)
    gif = os.path.join(out, "report_shake.gif")
    check(run.returncode == 0 and os.path.exists(gif), f"--animate shake writes {gif}: {run.stderr[-500:]}")
    if run.returncode:
        return
    frames = len(next(s for s in report["scenarios"] if s["name"] == "shake")["animation"]["frames"])
    with Image.open(gif) as im:
        check(im.n_frames == frames, f"the GIF has a frame per recorded frame: {im.n_frames} for {frames}")
        im.seek(0)
        first = im.convert("RGB")
        im.seek(frames // 2)
        middle = im.convert("RGB")
    check(sum(1 for p, q in zip(first.getdata(), middle.getdata()) if p != q) > 1000, "the GIF moves")
    check(os.path.getsize(gif) < 1 << 20, f"the GIF is under 1 MB: {os.path.getsize(gif)} bytes")
    bad = subprocess.run([sys.executable, charts_py, os.path.join(out, "report.json"), "--animate", "nowhere"],
                         capture_output=True, text=True)
    check(bad.returncode == 2 and "--animate nowhere" in bad.stderr and len(bad.stderr.strip().splitlines()) == 1,
          f"--animate of a scenario the report lacks: exit 2, one line: {bad.returncode} {bad.stderr!r}")


def main():
    hairbench, charts_py, out = sys.argv[1:4]
    shutil.rmtree(out, ignore_errors=True)
    run = subprocess.run([hairbench, "compare", "--scenario", "shake", "--scenario", "idle", "--frames", "144",
                          "--out", out], capture_output=True, text=True)
    if run.returncode != 0:
        print(run.stdout[-3000:], run.stderr[-3000:])
        return 1
    charts = load_charts(charts_py)
    report = json.load(open(os.path.join(out, "report.json")))

    opts = webdriver.ChromeOptions()
    opts.binary_location = CHROMIUM
    for a in ("--headless=new", "--no-sandbox", "--disable-gpu", "--window-size=1900,1400",
              "--disable-dev-shm-usage"):
        opts.add_argument(a)
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(CHROMEDRIVER), options=opts)
    try:
        driver.get("file://" + os.path.abspath(os.path.join(out, "report.html")))
        deadline = time.time() + 60
        while time.time() < deadline and not driver.execute_script("return hbPlayer.ready || hbPlayer.error"):
            time.sleep(0.2)
        check(driver.execute_script("return hbPlayer.ready"),
              f"the players are ready (error: {driver.execute_script('return hbPlayer.error')})")
        if failures:
            return 1
        names = driver.execute_script("return hbPlayer.players.map(p => p.sc.name)")
        check(names == ["shake", "idle"], f"one player per scenario, in order: {names}")
        ids = driver.execute_script("return hbPlayer.players.map(p => p.sc.id)")
        roots = [driver.find_element(By.ID, i) for i in ids]
        shake, idle = 0, 1
        panels = driver.execute_script("return hbPlayer.players[0].panels.length")
        models = [r["model"] for r in report["runs"] if r["scenario"] == "shake"]
        check(panels == len(models), f"shake has a panel per run: {panels} for {len(models)}")
        labels = driver.execute_script("return hbPlayer.players[0].panels.map(p => p.run.label)")
        ref = report["runs"][0]["metrics"]["deviation_vs_reference"]["reference"]
        check(labels and labels[0] == ref, f"the reference's panel first: {labels}")

        info = charts.scenario_info(report, "shake")
        anim = info["animation"]
        # Two frames of shake and of idle through the slider: blank, moving, still.
        frames = driver.execute_script("return hbPlayer.players[0].sc.frames.length")
        k1, k2 = frames // 2, frames // 2 + 3
        check(slider_to(driver, roots, shake, k1) == k1, f"the slider moved shake to recorded frame {k1}")
        shake_a = [canvas_image(driver, shake, p) for p in range(panels)]
        slider_to(driver, roots, shake, k2)
        shake_b = [canvas_image(driver, shake, p) for p in range(panels)]
        for p, (a, b) in enumerate(zip(shake_a, shake_b)):
            check(drawn(a) > 300, f"shake panel {labels[p]} draws strands at frame {k1}: {drawn(a)} pixels")
            check(differing(a, b) > 200, f"shake panel {labels[p]} moves from frame {k1} to {k2}: "
                                         f"{differing(a, b)} pixels differ")
        slider_to(driver, roots, idle, frames - 6)
        idle_a = canvas_image(driver, idle, 0)
        slider_to(driver, roots, idle, frames - 1)
        idle_b = canvas_image(driver, idle, 0)
        check(drawn(idle_a) > 300, "idle's reference panel draws strands")
        check(differing(idle_a, idle_b) < 0.1 * differing(shake_a[0], shake_b[0]),
              f"idle's reference holds still between its last frames: {differing(idle_a, idle_b)} pixels differ, "
              f"shake's {differing(shake_a[0], shake_b[0])}")

        # The drawn tips are the report's positions.
        slider_to(driver, roots, shake, k1)
        img = canvas_image(driver, shake, 0)
        sizes = [len(v) for v in anim["vertices"]]
        q = charts.decode_animation(anim["reference"]["data"], sizes)[k1]
        points = charts.animation_world(anim, k1, q)
        centre = driver.execute_script("return hbPlayer.players[arguments[0]].centre", shake)
        scale = driver.execute_script("return hbPlayer.players[arguments[0]].scale", shake)
        size = img.size[0]
        mean = [sum(h[a] for h in anim["head"]) / len(anim["head"]) for a in range(3)]
        check(max(abs(c - m) for c, m in zip(centre, mean)) < 1e-9, f"the view is centred on the head's mean {centre}")
        end, hits, far = 0, 0, 0.0
        for n in sizes:
            end += n
            tip = points[end - 1]
            (x, y), = charts.camera([tip], centre)
            px, py = 0.5 * size + x * scale, 0.5 * size - y * scale
            page = driver.execute_script("return hbPlayer.players[arguments[0]].pixel(arguments[1])", shake, list(tip))
            far = max(far, math.hypot(page[0] - px, page[1] - py))
            near = [img.getpixel((int(px) + dx, int(py) + dy)) for dx in (-1, 0, 1) for dy in (-1, 0, 1)
                    if 0 <= int(px) + dx < size and 0 <= int(py) + dy < size]
            hits += any(a > 0 and not (abs(r - g) < 8 and abs(g - b) < 8) for r, g, b, a in near)
        check(far < 0.01, f"the page projects the report's tips where the stills' camera does (within {far:.3g} px)")
        check(hits == len(sizes), f"every strand's tip is drawn where the report puts it: {hits} of {len(sizes)}")

        # Play, speed and pause.
        button = roots[shake].find_element(By.CLASS_NAME, "hb-play")
        speed = Select(roots[shake].find_element(By.CLASS_NAME, "hb-speed"))
        rate = {}
        # Long enough for a few frames at 1/4x, short of wrapping round at 2x.
        for label, seconds in (("0.25", 1.5), ("2", 0.5)):
            slider_to(driver, roots, shake, 0)
            speed.select_by_value(label)
            start = time.time()
            button.click()
            time.sleep(seconds)
            button.click()
            k = driver.execute_script("return hbPlayer.players[arguments[0]].k", shake)
            rate[label] = k / (time.time() - start)
        real = 1.0 / (anim["stride"] * info["dt"])
        check(0 < rate["0.25"] < 0.5 * real and rate["2"] > 4 * rate["0.25"],
              f"play advances, 8x faster at 2x than at 1/4x: {rate} recorded frames a second "
              f"(the recording's {real:.3g} a second at 1x)")
        held = driver.execute_script("return hbPlayer.players[arguments[0]].k", shake)
        time.sleep(0.5)
        check(driver.execute_script("return hbPlayer.players[arguments[0]].k", shake) == held, "pause stops it")

        # Every recorded frame of shake once more, timed by the page. The bound is on the 95th
        # percentile: ctest runs other tests beside this one, and a draw the scheduler
        # preempts is the box's, not the player's; the worst may be three frames' time.
        driver.execute_script("const p = hbPlayer.players[arguments[0]]; hbPlayer.drawMs = [];"
                              "for (let k = 0; k < p.sc.frames.length; ++k) p.set(k);", shake)
        ms = sorted(driver.execute_script("return hbPlayer.drawMs"))
        p95 = ms[min(len(ms) - 1, int(0.95 * len(ms)))]
        check(p95 <= 33.0 and ms[-1] <= 100.0, f"a frame of {panels} panels draws in at most 33 ms: 95th percentile "
                                               f"{p95:.1f} ms, max {ms[-1]:.1f} ms over {len(ms)} frames")
        print(f"draw: 95th percentile {p95:.1f} ms, median {ms[len(ms) // 2]:.1f} ms, max {ms[-1]:.1f} ms over "
              f"{len(ms)} frames of {panels} panels")
        errors = [e for e in driver.get_log("browser") if e["level"] == "SEVERE"]
        check(not errors, f"no console errors: {errors[:3]}")
        slider_to(driver, roots, shake, k1)
        driver.execute_script("arguments[0].scrollIntoView()", roots[shake])
        roots[shake].screenshot(os.path.join(out, "player.png"))
    finally:
        driver.quit()
    check_gif(charts_py, out, report)
    if failures:
        print(f"{len(failures)} failures")
        return 1
    print(f"player_browser_test: all checks passed (screenshot {os.path.join(out, 'player.png')})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
