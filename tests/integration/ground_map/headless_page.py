#!/usr/bin/env python3
"""Loads a page in headless chromium, waits until a condition on the page holds, then writes what it drew.

    headless_page.py --browser PATH --profile DIR --size W,H --url URL --until JS [--dom FILE]
                     [--screenshot FILE] [--deadline S] [--log FILE]

chromium is driven over its DevTools pipe (--remote-debugging-pipe), one step at a time, each step against
the one deadline: start, open a page, load URL, wait until the JavaScript expression JS is true in the page
(polled every 100 ms), then the DOM (doctype and outerHTML) to --dom and a PNG of the W x H viewport to
--screenshot. The page runs on the real clock: no virtual time, whose budget a page with a long-lived request
can keep from ever running out. When a step does not finish in time, the message names it (and, for the
wait, the expression's last value), the browser's process group is killed and the exit status is 1.
"""
import argparse
import base64
import fcntl
import json
import os
import select
import signal
import sys
import time


class StepFailed(Exception):
    pass


class Browser:
    """A headless chromium on a DevTools pipe: commands written to its fd 3, answers read from its fd 4."""

    def __init__(self, path, profile, width, height, log_path):
        to_browser_r, to_browser_w = os.pipe()
        from_browser_r, from_browser_w = os.pipe()
        # posix_spawn's dup2 onto 3 and 4 must not land on one of the pipes themselves.
        ends = [fcntl.fcntl(fd, fcntl.F_DUPFD_CLOEXEC, 10) for fd in (to_browser_r, from_browser_w)]
        args = [path, '--headless', '--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage', '--no-first-run',
                '--hide-scrollbars', '--remote-debugging-pipe', '--window-size=%d,%d' % (width, height),
                '--user-data-dir=' + profile, 'about:blank']
        actions = [(os.POSIX_SPAWN_OPEN, 0, os.devnull, os.O_RDONLY, 0),
                   (os.POSIX_SPAWN_OPEN, 1, log_path, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o644),
                   (os.POSIX_SPAWN_OPEN, 2, log_path, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o644),
                   (os.POSIX_SPAWN_DUP2, ends[0], 3),
                   (os.POSIX_SPAWN_DUP2, ends[1], 4)]
        self.pid = os.posix_spawn(path, args, os.environ, file_actions=actions, setpgroup=0)
        self.group = self.pid
        for fd in ends + [to_browser_r, from_browser_w]:
            os.close(fd)
        self.out = to_browser_w
        self.inp = from_browser_r
        self.buffer = b''
        self.next_id = 0
        self.width = width
        self.height = height

    def send(self, method, params, session, deadline, step):
        """One command; its result (the events in between are dropped)."""
        self.next_id += 1
        message = {'id': self.next_id, 'method': method, 'params': params}
        if session:
            message['sessionId'] = session
        data = json.dumps(message).encode() + b'\0'
        while data:
            wait(None, self.out, deadline, step)
            data = data[os.write(self.out, data):]
        while True:
            answer = self.receive(deadline, step)
            if answer.get('id') == self.next_id:
                if 'error' in answer:
                    raise StepFailed('%s: %s answered %s' % (step, method, answer['error'].get('message')))
                return answer.get('result', {})

    def receive(self, deadline, step):
        while b'\0' not in self.buffer:
            wait(self.inp, None, deadline, step)
            chunk = os.read(self.inp, 1 << 16)
            if not chunk:
                raise StepFailed('%s: the browser closed its DevTools pipe (it ended?)' % step)
            self.buffer += chunk
        message, self.buffer = self.buffer.split(b'\0', 1)
        return json.loads(message)

    def close(self, deadline):
        """Browser.close, then its end (the answer may not come: the pipe closes with it)."""
        self.next_id += 1
        os.write(self.out, json.dumps({'id': self.next_id, 'method': 'Browser.close'}).encode() + b'\0')
        while time.monotonic() < deadline:
            pid, _ = os.waitpid(self.pid, os.WNOHANG)
            if pid:
                self.pid = None
                return
            time.sleep(0.05)

    def kill(self):
        """Its whole process group (renderers, zygote), whatever state it is in."""
        try:
            os.killpg(self.group, signal.SIGKILL)
        except ProcessLookupError:
            pass
        if self.pid is not None:
            os.waitpid(self.pid, 0)


def wait(readable, writable, deadline, step):
    left = deadline - time.monotonic()
    if left <= 0:
        raise StepFailed('%s: not done in time' % step)
    r, w, _ = select.select([readable] if readable is not None else [],
                            [writable] if writable is not None else [], [], left)
    if not r and not w:
        raise StepFailed('%s: not done in time' % step)


def evaluate(browser, session, expression, deadline, step):
    result = browser.send('Runtime.evaluate', {'expression': expression, 'returnByValue': True}, session,
                          deadline, step)
    if 'exceptionDetails' in result:
        details = result['exceptionDetails']
        text = details.get('exception', {}).get('description') or details.get('text')
        raise StepFailed('%s: the expression threw: %s' % (step, text))
    return result.get('result', {}).get('value')


def run(args, browser, deadline):
    step = 'open a page'
    target = browser.send('Target.createTarget', {'url': 'about:blank'}, None, deadline, step)['targetId']
    session = browser.send('Target.attachToTarget', {'targetId': target, 'flatten': True}, None, deadline,
                           step)['sessionId']
    browser.send('Emulation.setDeviceMetricsOverride',
                 {'width': browser.width, 'height': browser.height, 'deviceScaleFactor': 1, 'mobile': False},
                 session, deadline, step)
    browser.send('Page.enable', {}, session, deadline, step)

    step = 'load ' + args.url
    loaded = browser.send('Page.navigate', {'url': args.url}, session, deadline, step)
    if loaded.get('errorText'):
        raise StepFailed('%s: %s' % (step, loaded['errorText']))

    step = 'wait until ' + args.until
    condition = 'document.readyState === "complete" && !!(%s)' % args.until
    while evaluate(browser, session, condition, deadline, step) is not True:
        if time.monotonic() + 0.1 >= deadline:
            last = evaluate(browser, session, 'JSON.stringify([document.readyState, %s])' % args.until,
                            time.monotonic() + 5, step)
            raise StepFailed('%s: not true in time (last: the document %s, the expression %s)'
                             % ((step,) + tuple(json.loads(last or '[null, null]'))))
        time.sleep(0.1)

    if args.dom:
        step = 'dump the DOM'
        dom = evaluate(browser, session,
                       '(document.doctype ? new XMLSerializer().serializeToString(document.doctype) + "\\n" : "")'
                       ' + document.documentElement.outerHTML', deadline, step)
        with open(args.dom, 'w', encoding='utf-8') as out:
            out.write(dom + '\n')
    if args.screenshot:
        step = 'take the screenshot'
        shot = browser.send('Page.captureScreenshot', {'format': 'png'}, session, deadline, step)
        with open(args.screenshot, 'wb') as out:
            out.write(base64.b64decode(shot['data']))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--browser', required=True)
    parser.add_argument('--profile', required=True, help='a directory of its own for the browser profile')
    parser.add_argument('--size', default='1000,700', help='the viewport, W,H')
    parser.add_argument('--url', required=True)
    parser.add_argument('--until', required=True, help='a JavaScript expression; the page is taken once true')
    parser.add_argument('--dom', help='where the DOM goes')
    parser.add_argument('--screenshot', help='where the PNG goes')
    parser.add_argument('--deadline', type=float, default=90, help='seconds for all steps (default 90)')
    parser.add_argument('--log', default=os.devnull, help="where the browser's own messages go")
    args = parser.parse_args()
    width, height = (int(v) for v in args.size.split(','))
    started = time.monotonic()
    deadline = started + args.deadline
    try:
        browser = Browser(args.browser, args.profile, width, height, args.log)
    except OSError as e:
        print('headless_page: cannot start %s: %s' % (args.browser, e), file=sys.stderr)
        return 1
    try:
        run(args, browser, deadline)
        browser.close(time.monotonic() + 10)
    except StepFailed as e:
        print('headless_page: %s (after %.1f s of %g)' % (e, time.monotonic() - started, args.deadline),
              file=sys.stderr)
        return 1
    finally:
        browser.kill()
    return 0


if __name__ == '__main__':
    sys.exit(main())
