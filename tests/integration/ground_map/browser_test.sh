#!/usr/bin/env bash
# Loads the map page from airseg-map-fixture (a plan, a vehicle driving it) in headless chromium and checks
# what the page drew: the plan's lines, areas, holds and no-fly zone, the vehicle marker and a moving track
# (from the DOM the browser dumps), the plan's progress in plan terms, its numbered waypoints with the next
# target highlighted, one event line per waypoint (the slots only in the debug view), the link box and the
# position's age in an outage, and that a screenshot is a PNG with content.
#
#   browser_test.sh PATH/TO/airseg-map-fixture
set -euo pipefail
fixture=${1:?airseg-map-fixture}
. "$(dirname "$0")/headless_map.sh"

# Starts the fixture for $1 seconds (the rest: its options).
start_fixture() {
  launch_fixture --seconds "$@"
}

# The fixture runs a few seconds (the vehicle moves 10 times a second) and then ends the page's event
# stream; the page keeps its picture (?for=60: a snapshot, longer than the fixture) and says its snapshot is
# over, and the browser then dumps what it drew ($1, the rest: more conditions, then headless_page.py's
# options).
snapshot() {
  local page=$1 more=$2
  shift 2
  capture_page --size 1200,800 --url "$page" --until "airsegMap.state().snapshot_over$more" "$@"
}

# The vehicle's first samples come before a GPS fix (0,0, flagged as no position), as on every bench.
start_fixture 4 --fixless-first 5
snapshot "${url}?for=60" "" --dom "$work/dom.html" || {
  echo "FAIL: chromium failed:" >&2
  tail -20 "$work/browser.log" >&2
  exit 1
}

fail=0
check() {  # description, condition result
  if [ "$2" = yes ]; then echo "ok: $1"; else echo "FAIL: $1" >&2; fail=1; fi
}
count() { grep -o "$1" "$work/dom.html" | wc -l; }
state=$(sed -n 's/.*<pre id="airseg-state"[^>]*>\([^<]*\)<\/pre>.*/\1/p' "$work/dom.html" | sed 's/&quot;/"/g; s/&lt;/</g; s/&gt;/>/g; s/&amp;/\&/g')
echo "page state: $state"
python3 - "$state" <<'PY' || fail=1
import json, sys
s = json.loads(sys.argv[1])
checks = [
    ("the plan's name", s["plan"] == "fixture <survey> & co"),
    ("5 plan elements drawn", s["plan_elements"] == 5),
    ("2 plan polylines (scan lines, orbit)", s["plan_lines"] == 2),
    ("1 scan area", s["plan_polygons"] == 1),
    ("1 hold", s["holds"] == 1),
    ("1 no-fly zone", s["no_fly"] == 1),
    ("the vehicle has a position", s["vehicle"] is not None),
    ("the vehicle is not at 0,0", s["vehicle"] is not None and abs(s["vehicle"]["lat"]) > 1),
    ("the track has no point without a fix (under 100 km; one at 0,0 adds 4,600)", 0 < s["track_m"] < 100000),
    ("the vehicle has a fix", s["no_fix"] is False),
    ("the track moved (more than one point)", s["track_points"] > 1),
    ("an event listed", s["events"] >= 1),
    ("the buttons are read-only", s["control"] is False),
]
bad = [name for name, ok in checks if not ok]
for name, ok in checks:
    print(("ok: " if ok else "FAIL: ") + name)
sys.exit(1 if bad else 0)
PY
# The same seen in the drawn SVG, not only in the page's own counts.
check "plan polylines in the SVG" "$([ "$(count 'class="airseg-plan-line')" -eq 2 ] && echo yes || echo no)"
check "no-fly polygon in the SVG" "$([ "$(count 'class="airseg-no-fly')" -eq 1 ] && echo yes || echo no)"
check "track polyline in the SVG" "$([ "$(count 'class="airseg-track')" -eq 1 ] && echo yes || echo no)"
check "vehicle marker" "$([ "$(count 'airseg-vehicle ')$(count 'airseg-vehicle"')" != 00 ] && echo yes || echo no)"
check "buttons disabled" "$(grep -q '<button id="btn-pause" type="button" disabled' "$work/dom.html" && echo yes || echo no)"

# The plan in plan terms: progress, numbered waypoints, the next target, one event line per waypoint.
python3 - "$state" "$work/dom.html" <<'PY' || fail=1
import html, json, re, sys
s = json.loads(sys.argv[1])
dom = open(sys.argv[2]).read()
events = re.search(r'<ol id="events"[^>]*>(.*?)</ol>', dom, re.S)
lines = [html.unescape(re.sub(r'<[^>]+>', '', li)).strip()[9:]
         for li in re.findall(r'<li[^>]*>(.*?)</li>', events.group(1) if events else '', re.S)]
reached = [l for l in lines if re.fullmatch(r'waypoint \d+ of 14 reached', l)]
labels = re.findall(r'class="[^"]*airseg-wp[ "][^>]*data-index="(\d+)"[^>]*>(\d+)<', dom)
nexts = re.findall(r'class="[^"]*airseg-wp-next[^"]*"[^>]*data-index="(\d+)"[^>]*>(\d+)<', dom)
progress = re.search(r'<div id="plan-progress">([^<]*)</div>', dom)
progress = html.unescape(progress.group(1)) if progress else ''
print("progress: " + progress)
print("event lines: " + repr(lines[:6]))
checks = [
    ("the plan's waypoint count (plan.show's) is known", s["waypoints"] == 14),
    ("all 14 waypoints numbered", s["numbered"] == 14 and len(labels) == 14),
    ("numbered from 1 in plan order", sorted(int(n) for _, n in labels) == list(range(1, 15))
        and all(int(n) == int(i) + 1 for i, n in labels)),
    ("one next target highlighted", len(nexts) == 1),
    ("the highlighted one is the telemetry's next waypoint",
        len(nexts) == 1 and s["next_waypoint"] is not None and int(nexts[0][0]) == s["next_waypoint"]),
    ("progress: state, waypoint k of 14, the element, distance left",
        re.fullmatch(r"running — waypoint \d+ of 14 — (waypoint 'start'|waypoint plan\.elements\[1\]|scan 'field'|"
                     r"hold 'wait'|orbit plan\.elements\[4\]) — [\d.]+ k?m left( \(about \d+ (s|min)\))?", progress)
        is not None),
    ("the progress names the next waypoint", s["next_waypoint"] is not None
        and ("waypoint %d of 14" % (s["next_waypoint"] + 1)) in progress),
    ("waypoints reached are listed (at least 3)", len(reached) >= 3),
    ("one line per waypoint: nothing else listed but the plan's note",
        all(l in reached or l == 'plan fixture <survey> loaded & running' for l in lines)),
    ("no waypoint said twice in a row", all(a != b for a, b in zip(reached, reached[1:]))),
    ("no slot number, board text or no-op mode change listed",
        not any(w in l for l in lines for w in ('slot', '#', 'Flight plan received', 'AUTO -> AUTO'))),
    ("the six events of each waypoint reached the page (5 as debug lines)", s["events"] >= 6 * len(reached)),
    ("the debug view is off", s["debug"] is False),
]
for name, ok in checks:
    print(("ok: " if ok else "FAIL: ") + name)
sys.exit(0 if all(ok for _, ok in checks) else 1)
PY

# The debug view (?debug=1, the page's checkbox) lists every event in the vehicle's own words.
start_fixture 4
snapshot "${url}?debug=1&for=60" "" --dom "$work/dom-debug.html" || {
  echo "FAIL: chromium failed:" >&2
  tail -20 "$work/browser.log" >&2
  exit 1
}
check "debug view: the window's slots listed" "$(grep -q 'mission slot [0-9]* reached' "$work/dom-debug.html" && echo yes || echo no)"
check "debug view: the board's texts listed" "$(grep -q 'Reached waypoint #[0-9]' "$work/dom-debug.html" && echo yes || echo no)"
check "debug view: a reworded event shows the vehicle's words" \
  "$(grep -q 'waypoint [0-9]* of 14 reached \[plan waypoint [0-9]* reached\]' "$work/dom-debug.html" && echo yes || echo no)"

# A radio outage after 10 samples: the link box says since when and greys its last figures; the vehicle's
# position says how old it is, and its marker greys.
start_fixture 5 --outage-after 10
snapshot "${url}?for=60" " && airsegMap.state().position_age_s >= 3" --dom "$work/dom-outage.html" || {
  echo "FAIL: chromium failed:" >&2
  tail -20 "$work/browser.log" >&2
  exit 1
}
outage_state=$(sed -n 's/.*<pre id="airseg-state"[^>]*>\([^<]*\)<\/pre>.*/\1/p' "$work/dom-outage.html" | sed 's/&quot;/"/g; s/&lt;/</g; s/&gt;/>/g; s/&amp;/\&/g')
echo "link: $(grep -o '<div id="link-text">[^<]*' "$work/dom-outage.html") $(grep -o '<div id="link-last">[^<]*' "$work/dom-outage.html")"
echo "vehicle: $(grep -o '<div id="vehicle-age">[^<]*' "$work/dom-outage.html")"
check "the link box says down since HH:MM:SS" \
  "$(grep -Eq '<div id="link-text">down since [0-2][0-9]:[0-5][0-9]:[0-5][0-9]</div>' "$work/dom-outage.html" && echo yes || echo no)"
check "the last figures apart (greyed), not as the link now" \
  "$(grep -q '<div id="link-last">last: rtt 84 ms · loss 2.0 %</div>' "$work/dom-outage.html" && echo yes || echo no)"
check "the position says its age" \
  "$(grep -Eq '<div id="vehicle-age">position ([3-9]|[1-9][0-9]+) s old</div>' "$work/dom-outage.html" && echo yes || echo no)"
check "the vehicle marker greyed as stale" "$(grep -q 'airseg-stale' "$work/dom-outage.html" && echo yes || echo no)"
python3 - "$outage_state" <<'PY' || fail=1
import json, sys
s = json.loads(sys.argv[1])
checks = [
    ("page state: the link down", (s["link"] or {}).get("link") == "down" and "down_since" in (s["link"] or {})),
    ("page state: the position's age (3 s or more)", (s["position_age_s"] or 0) >= 3),
    ("page state: the vehicle kept its last place (10 samples)", s["track_points"] == 10),
]
for name, ok in checks:
    print(("ok: " if ok else "FAIL: ") + name)
sys.exit(0 if all(ok for _, ok in checks) else 1)
PY

# The fix lost after 10 samples: the vehicle stays where it was last known, greyed, and says "no fix".
start_fixture 4 --lose-fix-after 10
snapshot "${url}?for=60" "" --dom "$work/dom-nofix.html" || {
  echo "FAIL: chromium failed:" >&2
  tail -20 "$work/browser.log" >&2
  exit 1
}
nofix_state=$(sed -n 's/.*<pre id="airseg-state"[^>]*>\([^<]*\)<\/pre>.*/\1/p' "$work/dom-nofix.html" | sed 's/&quot;/"/g; s/&lt;/</g; s/&gt;/>/g; s/&amp;/\&/g')
echo "page state after the fix is lost: $nofix_state"
python3 - "$nofix_state" <<'PY' || fail=1
import json, sys
s = json.loads(sys.argv[1])
checks = [
    ("no fix said in the page state", s["no_fix"] is True),
    ("the vehicle kept its last known place", s["vehicle"] is not None and abs(s["vehicle"]["lat"]) > 1),
    ("the track kept only the positions with a fix (10)", s["track_points"] == 10),
]
for name, ok in checks:
    print(("ok: " if ok else "FAIL: ") + name)
sys.exit(0 if all(ok for _, ok in checks) else 1)
PY
check "the vehicle says no fix" "$(grep -q '<div id="vehicle-text">no fix (GPS fix type 1)' "$work/dom-nofix.html" && echo yes || echo no)"
check "the vehicle marker greyed" "$(grep -q 'airseg-no-fix' "$work/dom-nofix.html" && echo yes || echo no)"

# The attack: a page on another origin, opened in the operator's browser, POSTs a command to a map started
# with control ("no-cors": it cannot read the answer, and needs none). The map must refuse it and say so.
start_fixture 4 --control
attacker=$work/attacker
mkdir -p "$attacker"
cat >"$attacker/index.html" <<HTML
<!DOCTYPE html><html><body><pre id="result">pending</pre><script>
fetch('${url}api/command', { method: 'POST', mode: 'no-cors', headers: { 'Content-Type': 'text/plain' },
                             body: '{"cmd":"plan.pause"}' })
  .then(() => { document.getElementById('result').textContent = 'sent'; })
  .catch(e => { document.getElementById('result').textContent = 'failed: ' + e; });
</script></body></html>
HTML
python3 -m http.server 0 --bind 127.0.0.1 --directory "$attacker" >"$work/attacker.log" 2>&1 &
pids+=($!)
attacker_url=""
for _ in $(seq 100); do
  attacker_url=$(sed -n 's/^Serving HTTP on [^ ]* port \([0-9]*\).*/http:\/\/127.0.0.1:\1\//p' "$work/attacker.log")
  [ -n "$attacker_url" ] && break
  sleep 0.1
done
[ -n "$attacker_url" ] || { echo "FAIL: the attacker's page server did not start" >&2; cat "$work/attacker.log" >&2; exit 1; }
capture_page --url "$attacker_url" --until "document.getElementById('result').textContent !== 'pending'" \
  --dom "$work/attack.html" || true
echo "attacker page: $(grep -o '<pre id="result">[^<]*' "$work/attack.html" | sed 's/.*>//')"
for _ in $(seq 100); do
  grep -q "map: refused a command" "$fixture_out" && break
  sleep 0.1
done
check "the cross-origin command was refused and logged" \
  "$(grep -q "map: refused a command: a page from ${attacker_url%/} may not command the vehicle" "$fixture_out" && echo yes || echo no)"
check "the vehicle got no command" "$(grep -q 'vehicle got the command' "$fixture_out" && echo no || echo yes)"

start_fixture 4
snapshot "${url}?for=60" "" --screenshot "$work/map.png" || true
if [ ! -s "$work/map.png" ]; then
  echo "FAIL: no screenshot written" >&2
  tail -20 "$work/browser.log" >&2
  fail=1
else
  magic=$(head -c 8 "$work/map.png" | od -An -tx1 | tr -d ' \n')
  size=$(stat -c %s "$work/map.png")
  check "screenshot is a PNG ($size bytes)" "$([ "$magic" = 89504e470d0a1a0a ] && [ "$size" -gt 5000 ] && echo yes || echo no)"
fi
if [ -n "${AIRSEG_MAP_SCREENSHOT:-}" ] && [ -s "$work/map.png" ]; then
  cp "$work/map.png" "$AIRSEG_MAP_SCREENSHOT"
fi
exit $fail
