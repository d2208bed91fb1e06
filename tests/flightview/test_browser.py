"""The live view in a real browser: Debian's chromium driven by Selenium (chromium-driver) loads the page of a
`joyfly demo --view` flight, waits until it has drawn, and checks the screenshot: the 3D view shows the vehicle's
red front arms over a non-blank canvas, and the plot panels on the right show its orange position lines.

Notes from trials on 2 cores: WebGPU crashed under headless Chromium, so the page is opened with `&renderer=webgl`
and Chromium renders with SwiftShader (software GL); the page takes up to ~30 s to come up.
Set JOYFLY_VIEW_SCREENSHOT=FILE.png to keep a small copy of the screenshot, taken once the trail shows too
(docs/view.png was made so).
"""

from __future__ import annotations

import os
import re
import shutil
import time
from pathlib import Path
from typing import Any

import pytest
from support.view_process import require_rerun, view_process, wait_until

pytestmark = pytest.mark.slow  # processes or long flights: not in `make test-fast`

CHROMIUM_ARGS = ("--headless=new", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
                 "--ignore-gpu-blocklist", "--window-size=1024,576")
FLOWN_S = 15.0  # the script's moves are over (joyfly's take-off, then 5 s of sticks)
PAGE_TIMEOUT_S = 180.0  # ~30 s on 2 cores; minutes on a machine loaded by other work (software GL)
FRONT_ARM = (255, 40, 40)  # flightview.live: the vehicle's front arms
VEHICLE_LINE = (255, 160, 0)  # flightview.live.PALETTE[0]: the first vehicle's position lines
# take off (joyfly does it), fly a little north-east and turn, then hover until the test stops the demo
SCRIPT = """\
8    forward=0.5
+1.6 forward=0 right=0.5
+1.6 right=0 yaw=0.3
+2   yaw=0
+300 end
"""


def flight_time_s(lines: list[str]) -> float:
    """The time of joyfly's last plain status line, `[  12.34] ...`."""
    for line in reversed(lines):
        match = re.match(r"\[\s*([0-9.]+)\]", line)
        if match:
            return float(match.group(1))
    return 0.0


def chromium() -> tuple[str, str]:
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    driver = shutil.which("chromedriver")
    if browser is None or driver is None:
        pytest.skip("Chromium is not installed: apt-get install chromium chromium-driver (Debian) to run the "
                    "browser test of the live view.")
    return browser, driver


def start_browser(browser: str, driver: str) -> Any:
    try:
        from selenium import webdriver
    except ImportError:
        pytest.skip("selenium is not installed: pip install 'joyfly[test]' to run the browser test.")
    options = webdriver.ChromeOptions()
    for arg in CHROMIUM_ARGS:
        options.add_argument(arg)
    options.binary_location = browser
    return webdriver.Chrome(options=options, service=webdriver.ChromeService(driver))


def take_screenshot(browser: Any, shot: Path) -> bool:
    """A screenshot, or False when the renderer was too busy to answer this time (software GL on 2 cores)."""
    from selenium.common.exceptions import TimeoutException

    try:
        return bool(browser.save_screenshot(str(shot)))
    except TimeoutException:
        return False


def count_near(image: Any, colour: tuple[int, int, int], tolerance: int = 40) -> int:
    """Pixels within `tolerance` of `colour` on every channel."""
    r, g, b = colour
    return sum(1 for (pr, pg, pb) in pixels(image)
               if abs(pr - r) <= tolerance and abs(pg - g) <= tolerance and abs(pb - b) <= tolerance)


def pixels(image: Any) -> list[tuple[int, int, int]]:
    getter = getattr(image, "get_flattened_data", None) or image.getdata  # Pillow 13 renamed getdata
    return list(getter())


def drawn(shot: Path, with_trail: bool = False) -> tuple[bool, str]:
    """Whether the screenshot shows the 3D view (left 60%: not blank, the vehicle's red front arms) and the plot
    panels (right 40%: the vehicle's orange series); `with_trail`: its orange trail in the 3D view too."""
    from PIL import Image

    with Image.open(shot) as full:
        image = full.convert("RGB")
    width, height = image.size
    scene = image.crop((0, 40, int(width * 0.6), height - 40))
    plots = image.crop((int(width * 0.6), 40, width, height - 40))
    colours = len(set(pixels(scene)))
    arms, trail, lines = count_near(scene, FRONT_ARM), count_near(scene, VEHICLE_LINE), count_near(plots, VEHICLE_LINE)
    report = (f"3D view: {colours} colours, {arms} front-arm pixels, {trail} trail pixels; plots: {lines} pixels "
              "of the vehicle's series")
    return colours > 50 and arms > 20 and lines > 200 and (trail > 60 or not with_trail), report


def test_the_page_draws_the_vehicle_and_the_plots(tmp_path: Path) -> None:
    require_rerun()
    browser_path, driver_path = chromium()
    script = tmp_path / "hover.txt"
    script.write_text(SCRIPT)
    args = ["joyfly", "demo", "--plain", "--view", "--script", str(script)]
    shot = tmp_path / "view.png"
    keep = os.environ.get("JOYFLY_VIEW_SCREENSHOT")
    with view_process(args, tmp_path) as view:
        # Let it fly the script first: the viewer's server keeps what was logged and a page that connects later
        # takes it in at once (a page streaming live on a loaded machine with software GL falls far behind).
        assert wait_until(lambda: flight_time_s(view.output) >= FLOWN_S, 90), "the demo did not fly"
        browser = start_browser(browser_path, driver_path)
        try:
            browser.get(view.url + "&renderer=webgl")
            ok, report = False, "no screenshot"
            deadline = time.monotonic() + PAGE_TIMEOUT_S
            while not ok and time.monotonic() < deadline:
                time.sleep(3)
                if take_screenshot(browser, shot):
                    ok, report = drawn(shot, with_trail=bool(keep))
            canvases = browser.execute_script("return document.querySelectorAll('canvas').length")
        finally:
            browser.quit()
    assert canvases >= 1
    assert ok, report
    if keep:
        save_small(shot, Path(keep))


def save_small(shot: Path, target: Path) -> None:
    """A README-sized copy: 960 px wide, 256 colours."""
    from PIL import Image

    with Image.open(shot) as image:
        small = image.convert("RGB").resize((960, int(960 * image.height / image.width)), Image.Resampling.LANCZOS)
    small.quantize(colors=256, method=Image.Quantize.FASTOCTREE).save(target, optimize=True)
