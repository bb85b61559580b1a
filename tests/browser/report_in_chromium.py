#!/usr/bin/env python3
"""Renders `rollsim diagnose --report` in headless Chromium and checks it as a reader sees it.

Generates the report from a shipped real recording, opens it in Chromium (through chromedriver and Selenium) at a
desktop width and at a 390 px phone width, and fails when: the browser logs a SEVERE console entry; the page loads
any resource (it must be self-contained); a figure is missing, has zero size, draws no data or rasterises blank
(pixel variance on a canvas); the page overflows the phone viewport sideways outside a scroll container; the raw
text is not folded away; a headline, findings or detection-limits section is missing. Saves screenshots (PNG) to
--out and prints their paths. Exits 77 (ctest SKIP_RETURN_CODE) only when Chromium is not installed.
"""
import argparse
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile
import time

SKIP = 77
CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                  "--disable-background-networking", "--disable-component-update", "--disable-sync",
                  "--disable-dev-shm-usage", "--hide-scrollbars"]
# Phone: an iPhone 12-15's CSS viewport. Desktop: a laptop window.
VIEWPORTS = [("desktop", 1100, 900, False), ("phone", 390, 844, True)]

# Runs in the page; returns what the checks need. Each figure is serialised and drawn onto a white canvas at its
# laid-out size: a figure that draws nothing leaves every pixel white (variance 0).
PAGE_PROBE = r"""
const done = arguments[arguments.length - 1];
(async () => {
  const vw = document.documentElement.clientWidth;
  const out = {figures: [], overflow: [], scrollWidth: document.documentElement.scrollWidth, viewport: vw,
               resources: performance.getEntriesByType('resource').map(e => e.name),
               headline: (document.querySelector('#headline') || {}).textContent || '',
               sections: ['findings', 'regimes', 'residuals', 'limits', 'raw'].filter(id => document.getElementById(id)),
               rawOpen: !!(document.querySelector('details#raw') || {}).open,
               preOutsideDetails: [...document.querySelectorAll('pre')].filter(p => !p.closest('details')).length};
  for (const fig of document.querySelectorAll('figure')) {
    const svg = fig.querySelector('svg');
    const f = {id: fig.id, present: !!svg, width: 0, height: 0, dataElements: 0, inkFraction: 0, variance: 0};
    out.figures.push(f);
    if (!svg) continue;
    const r = svg.getBoundingClientRect();
    f.width = r.width; f.height = r.height;
    // gnuplot puts each plotted series in <g id="..gnuplot_plot_N">: count what it drew there.
    for (const g of svg.querySelectorAll('g[id*="gnuplot_plot_"]'))
      for (const el of g.querySelectorAll('path, use, polyline, circle, rect')) {
        const b = el.getBBox();
        if (b.width > 0 || b.height > 0) f.dataElements++;
      }
    const w = Math.max(1, Math.round(r.width)), h = Math.max(1, Math.round(r.height));
    const img = new Image();
    img.src = 'data:image/svg+xml;charset=utf-8,' + encodeURIComponent(new XMLSerializer().serializeToString(svg));
    try { await img.decode(); } catch (e) { f.decodeError = String(e); continue; }
    const c = document.createElement('canvas');
    c.width = w; c.height = h;
    const g = c.getContext('2d');
    g.fillStyle = '#fff'; g.fillRect(0, 0, w, h);
    g.drawImage(img, 0, 0, w, h);
    const px = g.getImageData(0, 0, w, h).data;
    let sum = 0, sum2 = 0, ink = 0;
    for (let i = 0; i < px.length; i += 4) {
      const y = 0.299 * px[i] + 0.587 * px[i + 1] + 0.114 * px[i + 2];
      sum += y; sum2 += y * y; if (y < 250) ink++;
    }
    const n = px.length / 4;
    f.variance = sum2 / n - (sum / n) * (sum / n);
    f.inkFraction = ink / n;
  }
  // Anything reaching past the viewport's right edge must sit inside a horizontal scroll container.
  for (const el of document.body.querySelectorAll('*')) {
    const r = el.getBoundingClientRect();
    if (r.width === 0 || r.right <= vw + 1) continue;
    let p = el.parentElement, inside = false;
    for (; p && p !== document.body; p = p.parentElement) {
      const o = getComputedStyle(p).overflowX;
      if ((o === 'auto' || o === 'scroll') && p.getBoundingClientRect().right <= vw + 1) { inside = true; break; }
    }
    if (!inside && out.overflow.length < 5) out.overflow.push(el.tagName + (el.id ? '#' + el.id : '') + ' right=' + Math.round(r.right));
  }
  done(out);
})();
"""


def find_chromium():
    for name in ("chromium", "chromium-browser"):
        path = shutil.which(name)
        if path:
            return path
    return None


# Two shipped real recordings: a Camry dynamometer test whose diagnosis fits a catalogue effect (findings table with
# intervals, share and held-out change), and a Twizy road trip (state of charge, grade from GPS elevation: the
# uphill/level/downhill regimes) whose residual no catalogue effect explains.
CASES = [
    ("camry_us06", "camry_2018.yaml", "anl_d3", ["anl_d3_2018_toyota_camry/61811014_test_data.csv"]),
    ("twizy_trip", "twizy.yaml", "rsk_twizy", ["rsk_renault_twizy/T1_07_01_2021.csv"]),
]


def generate_report(args, case, report_dir):
    name, vehicle, preset, recordings = case
    cmd = [args.rollsim, "diagnose", "--vehicle", str(pathlib.Path(args.source) / "vehicles" / vehicle), "--preset", preset,
           "--report", str(report_dir)]
    for r in recordings:
        cmd += ["--recording", str(pathlib.Path(args.shared) / "data" / "recordings" / r)]
    t0 = time.monotonic()
    run = subprocess.run(cmd, capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit("FAIL: %s: rollsim diagnose --report exited %d\n%s%s" % (name, run.returncode, run.stdout, run.stderr))
    print("%s: report generated in %.1f s: %s" % (name, time.monotonic() - t0, report_dir / "report.html"))
    return report_dir / "report.html"


def start_driver(chromium, profile_dir):
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    options = webdriver.ChromeOptions()
    options.binary_location = chromium
    for flag in CHROMIUM_FLAGS + ["--user-data-dir=" + profile_dir]:
        options.add_argument(flag)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver_path = shutil.which("chromedriver") or "/usr/bin/chromedriver"
    driver = webdriver.Chrome(service=Service(executable_path=driver_path), options=options)
    driver.set_script_timeout(60)
    return driver


def check_view(driver, url, name, width, height, mobile, out_dir):
    driver.execute_cdp_cmd("Emulation.setDeviceMetricsOverride",
                           {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": mobile})
    driver.get(url)
    probe = driver.execute_async_script(PAGE_PROBE)
    problems = []
    if not probe["headline"].strip():
        problems.append("no headline sentence")
    missing = {"findings", "regimes", "residuals", "limits", "raw"} - set(probe["sections"])
    if missing:
        problems.append("sections missing: %s" % sorted(missing))
    if probe["rawOpen"] or probe["preOutsideDetails"]:
        problems.append("the raw text is not folded away in a closed <details>")
    if probe["resources"]:
        problems.append("the page loaded resources (must be self-contained): %s" % probe["resources"][:5])
    if len(probe["figures"]) < 6:
        problems.append("expected at least 6 figures (regimes and 5 residual figures), found %d" % len(probe["figures"]))
    for f in probe["figures"]:
        if not f["present"] or f["width"] < 50 or f["height"] < 50:
            problems.append("figure %s missing or of no size (%.0f x %.0f px)" % (f["id"], f["width"], f["height"]))
        elif f.get("decodeError") or f["dataElements"] == 0 or f["variance"] < 50 or f["inkFraction"] < 0.005:
            problems.append("figure %s blank: %d data elements, pixel variance %.1f, ink %.2f %% %s" % (
                f["id"], f["dataElements"], f["variance"], 100 * f["inkFraction"], f.get("decodeError", "")))
    if probe["scrollWidth"] > probe["viewport"] + 1 or probe["overflow"]:
        problems.append("page wider than the %d px viewport (scrollWidth %d) outside scroll containers: %s" % (
            probe["viewport"], probe["scrollWidth"], probe["overflow"]))
    figures = ", ".join("%s %.0fx%.0f var %.0f" % (f["id"], f["width"], f["height"], f["variance"]) for f in probe["figures"])
    print("%s (%d px): %d figures [%s]; headline: %s" % (name, width, len(probe["figures"]), figures, probe["headline"]))
    # A screenshot of the page's top (headline, findings, first figures): the reader's first screen and a bit more.
    full = driver.execute_script("return document.documentElement.scrollHeight")
    driver.execute_cdp_cmd("Emulation.setDeviceMetricsOverride",
                           {"width": width, "height": min(full, 1500 if mobile else 1300), "deviceScaleFactor": 1,
                            "mobile": mobile})
    shot = out_dir / ("%s.png" % name)
    driver.save_screenshot(str(shot))
    print("screenshot: %s" % shot)
    return [name + ": " + p for p in problems], shot


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rollsim", required=True, help="the rollsim executable")
    ap.add_argument("--source", required=True, help="the repository's root (vehicles/)")
    ap.add_argument("--shared", required=True, help="the shared data folder (data/recordings/)")
    ap.add_argument("--out", required=True, help="folder for the report and the screenshots")
    ap.add_argument("--docs-screenshot", help="also copy the desktop screenshot here (the README's docs/report.png)")
    args = ap.parse_args()
    chromium = find_chromium()
    if not chromium:
        print("SKIP: chromium is not installed (Debian: apt-get install chromium chromium-driver python3-selenium)")
        return SKIP
    t0 = time.monotonic()
    out = pathlib.Path(args.out).resolve()
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir(parents=True)
    pages = [(case[0], generate_report(args, case, out / case[0])) for case in CASES]
    with tempfile.TemporaryDirectory(prefix="rollsim_chromium_") as profile:
        t1 = time.monotonic()
        driver = start_driver(chromium, profile)
        problems, shots = [], {}
        try:
            for case, html in pages:
                for view, width, height, mobile in VIEWPORTS:
                    name = case + "_" + view
                    p, shots[name] = check_view(driver, html.as_uri(), name, width, height, mobile, out)
                    problems += p
                problems += ["%s: console: %s" % (case, e.get("message"))
                             for e in driver.get_log("browser") if e.get("level") == "SEVERE"]
        finally:
            driver.quit()
    print("browser checks in %.1f s (total %.1f s)" % (time.monotonic() - t1, time.monotonic() - t0))
    if args.docs_screenshot:
        shutil.copyfile(shots[CASES[0][0] + "_desktop"], args.docs_screenshot)
        print("copied to %s" % args.docs_screenshot)
    for p in problems:
        print("FAIL: " + p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
