#!/usr/bin/env bash
# The map page at three moments of a survey (airseg-map-fixture --moment): leaving the start, mid-scan, and
# in a radio outage. For each, headless chromium (headless_page.py) dumps what the page drew once the moment's
# snapshot is over, and the test checks it: the plan's
# progress ("waypoint k of 14", the element, distance left), its 14 waypoints numbered with the next target
# highlighted, every track point the page draws inside the plan's area (and none in the no-fly zone), and in
# the outage the link box "down since" and the position's age. The same browser pictures the moment, and the
# test checks the picture is a PNG of the window's size.
#
#   moments_test.sh PATH/TO/airseg-map-fixture
#
# With AIRSEG_MAP_SCREENSHOTS=DIR the screenshots are kept there as map-start.png, map-mid-scan.png and
# map-outage.png (docs/images holds the ones the map's documentation shows).
set -euo pipefail
fixture=${1:?airseg-map-fixture}
web_dir=$(cd "$(dirname "$0")/../../../ground/map/web" && pwd)
. "$(dirname "$0")/headless_map.sh"
keep=${AIRSEG_MAP_SCREENSHOTS:-}
if [ -n "$keep" ] && [ ! -d "$keep" ]; then
  echo "FAIL: AIRSEG_MAP_SCREENSHOTS=$keep is not a directory" >&2
  exit 1
fi
width=1000
height=700

# Starts the fixture for $1 seconds (the rest: its options).
start_fixture() {
  launch_fixture --web-dir "$web_dir" --seconds "$@"
}

fail=0

# One moment: $1 its name, $2 the fixture's seconds, $3 the waypoint (1-based) the vehicle heads for,
# $4 the element's words in the progress. The page follows the vehicle for $2 seconds (?for=S: a snapshot,
# the page keeps its picture and does not say the hub is gone); once its stream has ended the browser dumps
# what the page drew and pictures it, in one go. A held moment is taken at once (its position still fresh:
# the page greys a position 3 s old), the outage once its position says its age.
moment() {
  local name=$1 seconds=$2 next=$3 element=$4
  echo "== moment: $name"
  local until='airsegMap.state().snapshot_over'
  [ "$name" = outage ] && until="$until && airsegMap.state().position_age_s >= 3"
  # The fixture outlives the snapshot (the test ends it).
  start_fixture 120 --moment "$name"
  local dom=$work/dom-$name.html png=$work/map-$name.png
  if ! capture_page --size "$width,$height" --url "${url}?for=$seconds&state=track" --until "$until" \
    --dom "$dom" --screenshot "$png"; then
    echo "FAIL: chromium failed ($name):" >&2
    tail -20 "$work/browser.log" >&2
    fail=1
    return
  fi
  kill "$fixture_pid" 2>/dev/null || true
  python3 - "$name" "$dom" "$next" "$element" <<'PY' || fail=1
import html, json, re, sys
name, dom_path, next_wp, element = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
dom = open(dom_path).read()
def div(id_):
    m = re.search(r'<div id="%s">([^<]*)</div>' % id_, dom)
    return html.unescape(m.group(1)) if m else None
state = re.search(r'<pre id="airseg-state"[^>]*>([^<]*)</pre>', dom)
s = json.loads(html.unescape(state.group(1))) if state else {}
progress = div('plan-progress') or ''
labels = re.findall(r'class="[^"]*airseg-wp[ "][^>]*data-index="(\d+)"[^>]*>(\d+)<', dom)
nexts = re.findall(r'class="[^"]*airseg-wp-next[^"]*"[^>]*data-index="(\d+)"[^>]*>(\d+)<', dom)
print("progress: " + progress)
print("link: %r %r; vehicle: %r" % (div('link-text'), div('link-last'), div('vehicle-age')))
track = s.get('track') or []
area = s.get('plan_area')
# The fixture's plan: its elements lie in this box (its no-fly zone, the pond, outside it).
fixture_area = [[41.2752, 1.9868], [41.2763, 1.9888]]
pond = [[41.2766, 1.9890], [41.2770, 1.9896]]
eps = 1e-7  # the wire's resolution
def inside(p, box):
    return box[0][0] - eps <= p[0] <= box[1][0] + eps and box[0][1] - eps <= p[1] <= box[1][1] + eps
outside = [p for p in track if not area or not inside(p, area)]
print("track: %d points, the plan's area %r" % (len(track), area))
checks = [
    ("the page drew its state", bool(s)),
    ("progress: running, waypoint %d of 14, %s, distance left" % (next_wp, element),
        re.fullmatch(r"running — waypoint %d of 14 — %s — [\d.]+ k?m left( \(about \d+ (s|min)\))?"
                     % (next_wp, re.escape(element)), progress) is not None),
    ("all 14 waypoints numbered, from 1 in plan order", s.get('numbered') == 14 and len(labels) == 14
        and all(int(n) == int(i) + 1 for i, n in labels)),
    ("waypoint %d highlighted as the next target" % next_wp,
        [int(n) for _, n in nexts] == [next_wp] and s.get('next_waypoint') == next_wp - 1),
    ("the plan's area is the fixture's", area is not None
        and all(abs(a - b) < 1e-9 for pa, pb in zip(area, fixture_area) for a, b in zip(pa, pb))),
    ("the track has points (%d)" % len(track), len(track) >= 2 and len(track) == s.get('track_points')),
    ("no track point outside the plan's area%s" % (" (%r)" % outside[:3] if outside else ""), not outside),
    ("no track point in the no-fly zone", not any(inside(p, pond) for p in track)),
    ("the track is the vehicle's way to where it is",
        bool(track) and s.get('vehicle') is not None
        and abs(track[-1][0] - s['vehicle']['lat']) < 1e-9 and abs(track[-1][1] - s['vehicle']['lon']) < 1e-9),
]
if name == 'outage':
    checks += [
        ("the link box says down since HH:MM:SS",
            re.fullmatch(r'down since [0-2]\d:[0-5]\d:[0-5]\d', div('link-text') or '') is not None),
        ("the link's last figures apart", div('link-last') == 'last: rtt 84 ms · loss 2.0 %'),
        ("the position says its age (3 s or more)",
            re.fullmatch(r'position ([3-9]|[1-9]\d+) s old', div('vehicle-age') or '') is not None
            and (s.get('position_age_s') or 0) >= 3),
        ("the vehicle marker greyed as stale", 'airseg-stale' in dom),
        ("the track stops where the link went down (26 samples)", len(track) == 26),
    ]
else:
    checks += [
        ("the link box says up", (div('link-text') or '').startswith('up · rtt 84 ms')),
        ("the position is fresh (no age said)", div('vehicle-age') == '' and s.get('position_age_s') is None),
    ]
for what, ok in checks:
    print(("ok: " if ok else "FAIL: ") + name + ": " + what)
sys.exit(0 if all(ok for _, ok in checks) else 1)
PY

  if [ ! -s "$png" ]; then
    echo "FAIL: $name: no screenshot written" >&2
    tail -20 "$work/browser.log" >&2
    fail=1
    return
  fi
  python3 - "$name" "$png" "$width" "$height" <<'PY' || fail=1
import struct, sys, os
name, path, w, h = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
data = open(path, 'rb').read(33)
ok_png = data[:8] == b'\x89PNG\r\n\x1a\n' and data[12:16] == b'IHDR'
pw, ph = struct.unpack('>II', data[16:24]) if ok_png else (0, 0)
size = os.path.getsize(path)
ok = ok_png and (pw, ph) == (w, h) and 5000 < size < 1000000
print(("ok: " if ok else "FAIL: ") + "%s: screenshot is a %dx%d PNG of %d bytes (%dx%d, 5 kB..1 MB wanted)"
      % (name, pw, ph, size, w, h))
sys.exit(0 if ok else 1)
PY
  if [ -n "$keep" ]; then
    cp "$png" "$keep/map-$name.png"
  fi
}

moment start 3 2 "waypoint plan.elements[1]"
moment mid-scan 3 6 "scan 'field'"
moment outage 5 8 "scan 'field'"
exit $fail
