#!/usr/bin/env python3
"""The rig's page in a real browser: headless chromium through chromedriver's WebDriver
protocol (W3C, plain HTTP and JSON: no package beyond python3 and Debian's chromium-driver).

usage: http_browser.py RIG_URL DRIVER_PORT SCREENSHOT.png

Loads the page, waits for its sliders and its first frame, moves the dimmer's slider to its
end with the keyboard (End: a real input event, as a user's), then waits until the page
shows the rig's new position (which comes back from the rig over the event stream, not from
the slider) and a newer frame; then the material's slider (a cycle control) to its last
value, until the page shows the rig's new material; and saves a screenshot. Prints one JSON line of what it saw;
exit status 0 when every step happened within its timeout, 1 otherwise (the reason on
stderr). tests/fw/test_fw_http.c runs it while the rig's loop runs, and checks the rig's own
state afterwards.
"""
import base64
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request

W3C_ELEMENT = "element-6066-11e4-a52e-4f735466cecf"


def call(base, method, path, body=None, timeout=30):
    data = None if body is None else json.dumps(body).encode()
    req = urllib.request.Request(base + path, data=data, method=method,
                                 headers={"Content-Type": "application/json"})
    try:
        with urllib.request.urlopen(req, timeout=timeout) as r:
            return json.loads(r.read() or b"{}").get("value")
    except urllib.error.HTTPError as e:
        raise RuntimeError(f"{method} {path}: {e.code} {e.read()[:400]!r}") from None


def wait(what, fn, timeout):
    end = time.monotonic() + timeout
    while True:
        v = fn()
        if v:
            return v
        if time.monotonic() > end:
            raise RuntimeError(f"timed out after {timeout} s waiting for {what}")
        time.sleep(0.05)


def main():
    url, port, shot = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    profile = tempfile.mkdtemp(prefix="lamprig-chromium-")
    log = open(os.path.join(profile, "driver.log"), "w")
    driver = subprocess.Popen(["chromedriver", f"--port={port}"], stdout=log,
                              stderr=subprocess.STDOUT)
    base = f"http://127.0.0.1:{port}"
    sid = None
    try:
        def ready():
            try:
                return call(base, "GET", "/status", timeout=1).get("ready")
            except (OSError, RuntimeError):
                return False
        wait("chromedriver", ready, 15)
        caps = {"capabilities": {"alwaysMatch": {
            "browserName": "chrome",
            "goog:chromeOptions": {
                "binary": shutil.which("chromium") or "/usr/bin/chromium",
                # Root in a container: no sandbox; no GPU; a fixed window for the screenshot.
                "args": ["--headless=new", "--no-sandbox", "--disable-gpu",
                         "--disable-dev-shm-usage", "--window-size=1280,680",
                         "--hide-scrollbars", f"--user-data-dir={profile}/p"]}}}}
        sid = call(base, "POST", "/session", caps, timeout=60)["sessionId"]
        s = f"/session/{sid}"

        def js(code, *args):
            return call(base, "POST", s + "/execute/sync", {"script": code, "args": list(args)})

        call(base, "POST", s + "/url", {"url": url})
        wait("the dimmer's slider", lambda: js("return !!document.getElementById('c-dimmer')"),
             15)
        frame0 = wait("the first frame",
                      lambda: js("const f=document.getElementById('frame');"
                                 "return f.complete&&f.naturalWidth>0&&f.dataset.frame"
                                 "?+f.dataset.frame:null"), 15)
        shown0 = js("return document.getElementById('v-dimmer').textContent")
        el = call(base, "POST", s + "/element",
                  {"using": "css selector", "value": "#c-dimmer"})[W3C_ELEMENT]
        call(base, "POST", s + f"/element/{el}/click", {})
        # End moves a range input to its maximum and fires input/change, as for a user.
        call(base, "POST", s + f"/element/{el}/value", {"text": "\ue010"})
        slider = js("return document.getElementById('c-dimmer').value")
        shown1 = wait("the rig's new position on the page",
                      lambda: (lambda t: t if t == "1.000" else None)(
                          js("return document.getElementById('v-dimmer').textContent")), 15)
        frame1 = wait("a newer frame",
                      lambda: (lambda f: f if f is not None and f > frame0 else None)(
                          js("const f=document.getElementById('frame');"
                             "return f.complete&&f.naturalWidth>0?+f.dataset.frame:null")), 15)
        # A cycle control: the material slider's end is its last value (index n - 1).
        el = call(base, "POST", s + "/element",
                  {"using": "css selector", "value": "#c-material"})[W3C_ELEMENT]
        call(base, "POST", s + f"/element/{el}/click", {})
        call(base, "POST", s + f"/element/{el}/value", {"text": "\ue010"})
        material = wait("the rig's new material on the page",
                        lambda: (lambda t: t if t == "marble" else None)(
                            js("return document.getElementById('v-material').textContent")), 15)
        # The page settles (the image decoded, the status rows filled) before the picture.
        time.sleep(0.3)
        png = base64.b64decode(call(base, "GET", s + "/screenshot"))
        with open(shot, "wb") as f:
            f.write(png)
        print(json.dumps({"slider": slider, "shown_before": shown0, "shown_after": shown1,
                          "frame_before": frame0, "frame_after": frame1, "material": material,
                          "screenshot_bytes": len(png)}))
        return 0
    except Exception as e:  # noqa: BLE001 - any failure is the test's failure, said once
        print(f"http_browser: {e}", file=sys.stderr)
        log.flush()
        with open(os.path.join(profile, "driver.log")) as f:
            sys.stderr.write(f.read()[-2000:])
        return 1
    finally:
        if sid:
            try:
                call(base, "DELETE", f"/session/{sid}", timeout=10)
            except (OSError, RuntimeError):
                pass
        driver.terminate()
        try:
            driver.wait(5)
        except subprocess.TimeoutExpired:
            driver.kill()
        log.close()
        shutil.rmtree(profile, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
