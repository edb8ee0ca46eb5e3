"""Open a report.html in headless Chromium and read back what the browser made of it.

Chromium is driven as a command (``--headless --dump-dom``): a copy of the page gets a small
script that, once the page has loaded, measures every image (``naturalWidth``: 0 for one
that did not load or decode) and every verdict box (its size, position, colours and the
text the reader sees) and writes them as JSON into the page, which Chromium then prints.
Nothing beyond the browser itself is needed: no driver, no Python package.

The browser is the first of ``$WOVENIMPACT_CHROMIUM`` or ``chromium``,
``chromium-headless-shell``, ``chromium-browser``, ``google-chrome`` or
``chrome-headless-shell`` found on the PATH (`make test` installs Debian's
``chromium-headless-shell`` when it runs as root with apt-get).
"""

from __future__ import annotations

import html
import json
import os
import re
import shutil
import subprocess
import tempfile
from pathlib import Path

NAMES = ("chromium", "chromium-headless-shell", "chromium-browser", "google-chrome",
         "chrome-headless-shell")
WINDOW = (1280, 900)  # the window a reader opens the page in (the screenshot's size)

CHECK_JS = """
<script id="browser-check-script">
window.addEventListener("load", function () {
  var box = function (e) {
    var r = e.getBoundingClientRect(), s = getComputedStyle(e);
    return {top: r.top + scrollY, bottom: r.bottom + scrollY, left: r.left,
            right: r.right, width: r.width, height: r.height, display: s.display,
            visibility: s.visibility, background: s.backgroundColor, color: s.color};
  };
  var out = {viewport: [innerWidth, innerHeight], images: [], verdicts: [], sections: {}};
  Array.prototype.forEach.call(document.images, function (img) {
    out.images.push({alt: img.alt, complete: img.complete, natural_width: img.naturalWidth,
                     natural_height: img.naturalHeight, box: box(img)});
  });
  Array.prototype.forEach.call(document.querySelectorAll(".verdict"), function (v) {
    out.verdicts.push({key: v.getAttribute("data-key"), status: v.getAttribute("data-status"),
                       in_trust: v.closest("#trust") !== null, text: v.innerText, box: box(v)});
  });
  ["verdicts", "trust", "summary", "pictures", "plots"].forEach(function (id) {
    var e = document.getElementById(id);
    if (e) { out.sections[id] = box(e); }
  });
  var pre = document.createElement("pre");
  pre.id = "browser-check";
  pre.textContent = JSON.stringify(out);
  document.body.appendChild(pre);
});
</script>
"""
RESULT = re.compile(r'<pre id="browser-check">(.*?)</pre>', re.S)


def find_chromium() -> str | None:
    """The path of a Chromium to drive, or None when there is none."""
    given = os.environ.get("WOVENIMPACT_CHROMIUM")
    if given:
        return shutil.which(given) or (given if Path(given).exists() else None)
    for name in NAMES:
        found = shutil.which(name)
        if found:
            return found
    return None


def chromium_args(chromium: str, window=WINDOW) -> list[str]:
    """The command line of a headless Chromium that needs no display, no GPU and no
    sandbox (the tests run as root in CI, where Chromium's sandbox refuses to start)."""
    return [chromium, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
            "--no-first-run", "--disable-extensions", "--mute-audio",
            f"--window-size={window[0]},{window[1]}"]


def open_in_browser(page: Path, scratch: Path, chromium: str, window=WINDOW,
                    timeout: float = 60.0) -> dict:
    """Load a copy of ``page`` (in ``scratch``, beside nothing else) in headless Chromium
    and return what the injected check measured: ``images`` (alt, natural_width, ...),
    ``verdicts`` (key, status, in_trust, text, box) and ``sections`` (box of #verdicts,
    #trust, ...), in CSS pixels from the top of the page."""
    text = Path(page).read_text(encoding="utf-8")
    assert "</body>" in text, f"{page}: no </body>"
    scratch.mkdir(parents=True, exist_ok=True)
    copy = scratch / "report.html"
    copy.write_text(text.replace("</body>", CHECK_JS + "</body>", 1), encoding="utf-8")
    done = subprocess.run(
        [*chromium_args(chromium, window), f"--user-data-dir={scratch.resolve() / 'profile'}",
         "--virtual-time-budget=10000", "--dump-dom", copy.resolve().as_uri()],
        capture_output=True, text=True, timeout=timeout, check=False)
    found = RESULT.search(done.stdout)
    assert found, (f"Chromium ran ({done.returncode}) but the page's check did not: "
                   f"{done.stderr[-2000:]}")
    return json.loads(html.unescape(found.group(1)))


def screenshot(page: Path, png: Path, chromium: str, window=WINDOW,
               timeout: float = 60.0) -> Path:
    """The top of ``page`` as a window of ``window`` pixels would show it, as a PNG."""
    png = Path(png).resolve()
    png.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as profile:
        subprocess.run([*chromium_args(chromium, window), f"--screenshot={png}",
                        f"--user-data-dir={profile}", Path(page).resolve().as_uri()],
                       capture_output=True, timeout=timeout, check=True)
    return png
