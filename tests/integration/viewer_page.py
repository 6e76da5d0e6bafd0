"""Loads the live viewer's page in headless Chromium and reports what it shows.

usage: viewer_page.py URL OUT_DIR [MIN_SNAPSHOTS]

Drives Chromium over the DevTools protocol on a pipe (--remote-debugging-pipe:
JSON messages ended by a NUL byte, on file descriptors 3 and 4), since the
page keeps its event stream open and a plain --dump-dom or --screenshot would
capture it before the first snapshot arrived. Waits until the page has drawn
at least MIN_SNAPSHOTS snapshots (default 1), then writes OUT_DIR/page.json
(the readouts' texts, the element ids, the body's data attributes) and
OUT_DIR/page.png (a screenshot). Exit code 1 with a message when the page
never gets there within the time limit.
"""

import base64
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

LIMIT = 60.0  # s for the whole session; a healthy page needs a second or two


class Browser:
    def __init__(self):
        to_browser_r, self._to_browser = os.pipe()
        self._from_browser, from_browser_w = os.pipe()
        # Inheritable, as dup2 onto the same number (a pipe may already be
        # on fd 3 or 4) keeps the close-on-exec flag.
        os.set_inheritable(to_browser_r, True)
        os.set_inheritable(from_browser_w, True)

        def child_fds():
            os.dup2(to_browser_r, 3)
            os.dup2(from_browser_w, 4)

        # A profile and a temporary folder of its own, removed on close:
        # left to itself Chromium leaves an org.chromium.Chromium.* folder
        # in /tmp after every run.
        self._scratch = tempfile.mkdtemp(prefix="ofn-chromium-")
        self.process = subprocess.Popen(
            ["chromium", "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
             "--window-size=1400,900", "--remote-debugging-pipe",
             "--user-data-dir=" + os.path.join(self._scratch, "profile"), "about:blank"],
            # The descriptors are put in place after the fork; fds 3 and 4
            # must then stay open, which close_fds would undo.
            close_fds=False, preexec_fn=child_fds,
            # Its own process group, so that close() ends the renderers and
            # helpers too: left running, they wrote into the scratch folder
            # after it was removed and it stayed in /tmp.
            start_new_session=True,
            env=dict(os.environ, TMPDIR=self._scratch),
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        os.close(to_browser_r)
        os.close(from_browser_w)
        self._buffer = b""
        self._next_id = 0
        self.session = None

    def call(self, method, params=None, deadline=None):
        self._next_id += 1
        message = {"id": self._next_id, "method": method, "params": params or {}}
        if self.session:
            message["sessionId"] = self.session
        os.write(self._to_browser, json.dumps(message).encode() + b"\0")
        while True:
            reply = self._read(deadline)
            if reply.get("id") == self._next_id:
                if "error" in reply:
                    raise RuntimeError("%s: %s" % (method, reply["error"]))
                return reply["result"]

    def _read(self, deadline):
        while b"\0" not in self._buffer:
            if deadline and time.monotonic() > deadline:
                raise TimeoutError("no answer from chromium")
            chunk = os.read(self._from_browser, 1 << 20)
            if not chunk:
                raise RuntimeError("chromium closed its pipe")
            self._buffer += chunk
        message, self._buffer = self._buffer.split(b"\0", 1)
        return json.loads(message)

    def close(self):
        try:
            os.killpg(self.process.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        self.process.wait()
        # A helper of the group may still be exiting: try a few times.
        for _ in range(20):
            shutil.rmtree(self._scratch, ignore_errors=True)
            if not os.path.exists(self._scratch):
                break
            time.sleep(0.1)


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__.strip().splitlines()[2])
    url, out = sys.argv[1], sys.argv[2]
    min_snapshots = int(sys.argv[3]) if len(sys.argv) == 4 else 1
    deadline = time.monotonic() + LIMIT
    browser = Browser()
    try:
        target = browser.call("Target.createTarget", {"url": url}, deadline)["targetId"]
        browser.session = browser.call("Target.attachToTarget",
                                       {"targetId": target, "flatten": True}, deadline)["sessionId"]
        probe = """JSON.stringify({
            body: Object.assign({}, document.body ? document.body.dataset : {}),
            ids: Array.from(document.querySelectorAll('[id]')).map(e => e.id),
            text: Object.fromEntries(Array.from(document.querySelectorAll('[id]'))
                                     .map(e => [e.id, e.textContent.trim()]))})"""
        while True:
            value = browser.call("Runtime.evaluate", {"expression": probe, "returnByValue": True},
                                 deadline)["result"].get("value")
            page = json.loads(value) if value else {"body": {}}
            if int(page["body"].get("snapshots", "0")) >= min_snapshots:
                break
            if time.monotonic() > deadline:
                sys.exit("the page drew %s snapshots in %.0f s, not %d"
                         % (page["body"].get("snapshots", "0"), LIMIT, min_snapshots))
            time.sleep(0.2)
        shot = browser.call("Page.captureScreenshot", {"format": "png"}, deadline)["data"]
        with open(os.path.join(out, "page.png"), "wb") as f:
            f.write(base64.b64decode(shot))
        with open(os.path.join(out, "page.json"), "w") as f:
            json.dump(page, f, indent=1)
    finally:
        browser.close()


if __name__ == "__main__":
    main()
