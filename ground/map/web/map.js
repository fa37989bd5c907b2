// The live map: the plan, the vehicle and its track, fed by the hub's server-sent events (/events).
(function () {
  'use strict';

  const map = L.map('map', { zoomControl: true, attributionControl: false }).setView([0, 0], 2);
  L.control.scale({ imperial: false }).addTo(map);

  // Offline background: a plain grid, so that the map works without any tile server.
  const Grid = L.GridLayer.extend({
    createTile: function () {
      const tile = document.createElement('canvas');
      const size = this.getTileSize();
      tile.width = size.x;
      tile.height = size.y;
      const ctx = tile.getContext('2d');
      ctx.strokeStyle = '#d6d6cf';
      ctx.lineWidth = 1;
      ctx.strokeRect(0.5, 0.5, size.x - 1, size.y - 1);
      return tile;
    }
  });
  let background = null;

  const planLayer = L.layerGroup().addTo(map);
  const trackLine = L.polyline([], { className: 'airseg-track', color: '#ff8c00', weight: 3 }).addTo(map);
  let vehicle = null;
  let fitted = false;
  let control = false;

  const counts = { elements: 0, lines: 0, polygons: 0, holds: 0, no_fly: 0 };
  let lastPosition = null;
  let noFix = false;
  let token = '';  // the map's own page is given it; commands carry it
  let planName = null;
  let linkState = null;
  let eventCount = 0;
  let debugView = false;
  let eventLog = [];        // every event the hub sent, debug lines included (the debug view shows them)
  let planWaypoints = null; // the expanded plan's count when known (the hub's plan.show), else null
  let planTop = [];         // the plan's top-level elements: path, kind, name, waypoints
  let route = [];           // the plan's waypoints in plan order, [lat, lon], when numbered (see drawPlan)
  let wpMarkers = [];       // their numbered markers (those drawn)
  let nextIndex = null;     // the plan's next waypoint (0-based index), from the telemetry
  let progressText = '';
  let planArea = null;      // the box around the plan's elements (the no-fly zones left out), when drawn
  // ?state=track: the page's state also lists the track's points (for a test; up to 10,000 of them, not
  // worth writing out at every sample otherwise).
  const stateTrack = new URLSearchParams(location.search).get('state') === 'track';
  let positionAt = null;    // when the last position was new, by this page's clock (ms)
  let positionAge = null;   // seconds, once older than kStaleSeconds
  let snapshotOver = false; // ?for=S: the stream has ended and the picture is kept
  const kStaleSeconds = 3;
  const kMostLabels = 300;  // more numbered waypoints than this: only the next target is labelled

  function trackLength() {
    const pts = trackLine.getLatLngs();
    let metres = 0;
    for (let i = 1; i < pts.length; i += 1) {
      metres += map.distance(pts[i - 1], pts[i]);
    }
    return metres;
  }
  function state() {
    return {
      plan: planName,
      plan_elements: counts.elements,
      plan_lines: counts.lines,
      plan_polygons: counts.polygons,
      holds: counts.holds,
      no_fly: counts.no_fly,
      track_points: trackLine.getLatLngs().length,
      track_m: Math.round(trackLength()),
      track: stateTrack ? trackLine.getLatLngs().map(p => [p.lat, p.lng]) : undefined,
      plan_area: planArea,
      vehicle: lastPosition ? { lat: lastPosition.lat, lon: lastPosition.lon, heading: lastPosition.heading } : null,
      link: linkState,
      events: eventCount,
      events_shown: document.getElementById('events').children.length,
      debug: debugView,
      control: control,
      no_fix: noFix,
      waypoints: planWaypoints,
      numbered: route.length,
      next_waypoint: nextIndex,
      progress: progressText,
      position_age_s: positionAge,
      snapshot_over: snapshotOver
    };
  }
  // Mirrored into the page so that a headless browser's DOM dump shows what is drawn.
  function publish() {
    document.getElementById('airseg-state').textContent = JSON.stringify(state());
  }
  window.airsegMap = { state: state, map: map };

  function latlngs(points) {
    return (points || []).filter(p => Array.isArray(p) && p.length >= 2).map(p => [p[0], p[1]]);
  }

  // The plan's waypoints in plan order, as the vehicle numbers them: the points of the main list's
  // elements (a scan's lines), when they are exactly the plan's waypoint count (no repeat or jump expands
  // them otherwise, nothing truncated). Otherwise none: no number is better than a wrong one.
  function planRoute(plan) {
    if (!plan || plan.truncated || typeof plan.waypoints !== 'number') {
      return [];
    }
    const pts = [];
    (plan.elements || []).forEach(e => {
      if (!String(e.path || '').startsWith('plan.blocks')) {
        latlngs(e.closed ? e.lines : e.points).forEach(p => pts.push(p));
      }
    });
    return pts.length === plan.waypoints ? pts : [];
  }

  function waypointIcon(n, next) {
    return L.divIcon({ className: 'airseg-wp' + (next ? ' airseg-wp-next' : ''), html: String(n),
                       iconSize: next ? [26, 26] : [18, 18], iconAnchor: next ? [13, 13] : [9, 9] });
  }

  function drawNumbers() {
    wpMarkers.forEach(m => planLayer.removeLayer(m));
    wpMarkers = [];
    const label = (i) => {
      const next = i === nextIndex;
      const m = L.marker(route[i], { icon: waypointIcon(i + 1, next), keyboard: false, interactive: false,
                                     zIndexOffset: next ? 1000 : 0 }).addTo(planLayer);
      m.getElement().dataset.index = String(i);
      wpMarkers.push(m);
    };
    if (route.length <= kMostLabels) {
      route.forEach((_, i) => label(i));
    } else if (nextIndex != null && nextIndex < route.length) {
      label(nextIndex);
    }
  }

  function drawPlan(plan) {
    planLayer.clearLayers();
    wpMarkers = [];
    Object.keys(counts).forEach(k => { counts[k] = 0; });
    planName = plan && plan.name ? plan.name : null;
    planWaypoints = plan && typeof plan.waypoints === 'number' ? plan.waypoints : null;
    planTop = (plan && plan.top) || [];
    route = planRoute(plan);
    document.getElementById('plan-name').textContent = planName ? planName : 'no plan';
    const bounds = L.latLngBounds([]);
    const area = L.latLngBounds([]);
    const mainRoute = [];
    ((plan && plan.elements) || []).forEach((e, i) => {
      const pts = latlngs(e.points);
      // Detached blocks run only when jumped to: they are drawn, but not joined to the main route.
      const route = String(e.path || '').startsWith('plan.blocks') ? [] : mainRoute;
      const title = (e.name ? e.name + ' — ' : '') + e.kind + ' ' + e.path;
      counts.elements += 1;
      pts.forEach(p => { bounds.extend(p); area.extend(p); });
      latlngs(e.lines).forEach(p => area.extend(p));
      if (e.closed && pts.length >= 3) {
        L.polygon(pts, { className: 'airseg-plan-area airseg-plan-el-' + i, color: '#1f6feb', weight: 1,
                         fillOpacity: 0.08 }).bindTooltip(title).addTo(planLayer);
        counts.polygons += 1;
        const lines = latlngs(e.lines);
        if (lines.length >= 2) {
          L.polyline(lines, { className: 'airseg-plan-line airseg-plan-el-' + i, color: '#1f6feb', weight: 2 })
            .bindTooltip(title).addTo(planLayer);
          counts.lines += 1;
        }
        lines.forEach(p => route.push(p));
      } else if (e.kind === 'hold') {
        pts.forEach(p => {
          L.circleMarker(p, { className: 'airseg-plan-hold airseg-plan-el-' + i, radius: 7, color: '#8250df' })
            .bindTooltip(title + (e.hold_s == null ? ' (until released)' : ' (' + e.hold_s + ' s)'))
            .addTo(planLayer);
          counts.holds += 1;
          route.push(p);
        });
      } else if (pts.length === 1) {
        L.circleMarker(pts[0], { className: 'airseg-plan-point airseg-plan-el-' + i, radius: 4, color: '#1f6feb' })
          .bindTooltip(title).addTo(planLayer);
        route.push(pts[0]);
      } else if (pts.length > 1) {
        L.polyline(pts, { className: 'airseg-plan-line airseg-plan-el-' + i, color: '#1f6feb', weight: 2 })
          .bindTooltip(title).addTo(planLayer);
        counts.lines += 1;
        pts.forEach(p => route.push(p));
      }
    });
    if (mainRoute.length >= 2) {
      L.polyline(mainRoute, { className: 'airseg-plan-route', color: '#1f6feb', weight: 1, dashArray: '4 4' })
        .addTo(planLayer);
    }
    ((plan && plan.no_fly) || []).forEach(z => {
      const pts = latlngs(z.points);
      if (pts.length >= 3) {
        L.polygon(pts, { className: 'airseg-no-fly', color: '#d1242f', weight: 2, fillOpacity: 0.25 })
          .bindTooltip('no-fly: ' + z.name).addTo(planLayer);
        counts.no_fly += 1;
        pts.forEach(p => bounds.extend(p));
      }
    });
    planArea = area.isValid() ? [[area.getSouth(), area.getWest()], [area.getNorth(), area.getEast()]] : null;
    if (plan && plan.truncated) {
      addEvent({ text: 'the plan is drawn in part: it has more points than a map answer carries' });
    }
    if (bounds.isValid()) {
      map.fitBounds(bounds.pad(0.15));
      fitted = true;
    }
    drawNumbers();
    showProgress();
    publish();
  }

  function metres(m) {
    return m >= 1000 ? (m / 1000).toFixed(1) + ' km' : Math.round(m) + ' m';
  }

  // "running — waypoint 4 of 12 — scan 'north field' — 2.1 km left": where the plan is, in plan terms.
  function showProgress() {
    const p = lastPosition;
    const box = document.getElementById('plan-progress');
    if (!p || !p.plan || p.plan === 'none') {
      progressText = planName ? 'no plan running' : '';
      box.textContent = progressText;
      return;
    }
    const parts = [p.plan];
    const driving = p.plan === 'running' || p.plan === 'paused';
    if (driving && nextIndex != null) {
      parts.push('waypoint ' + (nextIndex + 1) + (planWaypoints != null && nextIndex < planWaypoints
        ? ' of ' + planWaypoints : ''));
    }
    const el = planTop[p.plan_element];
    if (driving && el) {
      parts.push(el.kind + (el.name ? " '" + el.name + "'" : ' ' + el.path));
    }
    if (driving && route.length && nextIndex != null && nextIndex < route.length) {
      let left = map.distance([p.lat, p.lon], route[nextIndex]);
      for (let i = nextIndex + 1; i < route.length; i += 1) {
        left += map.distance(route[i - 1], route[i]);
      }
      let text = metres(left) + ' left';
      if (p.speed > 0.3) {
        const s = left / p.speed;  // at the present speed
        text += ' (about ' + (s < 90 ? Math.max(1, Math.round(s)) + ' s' : Math.round(s / 60) + ' min') + ')';
      }
      parts.push(text);
    }
    progressText = parts.join(' — ');
    box.textContent = progressText;
  }

  function vehicleIcon(heading) {
    const svg = '<svg width="28" height="28" viewBox="-14 -14 28 28" style="transform: rotate(' + (heading || 0) +
                'deg)"><path d="M0,-12 L8,10 L0,5 L-8,10 Z" fill="#ff8c00" stroke="#000" stroke-width="1.5"/></svg>';
    return L.divIcon({ className: 'airseg-vehicle-icon', html: svg, iconSize: [28, 28], iconAnchor: [14, 14] });
  }

  function setPosition(p, addToTrack) {
    lastPosition = p;
    noFix = false;
    positionAt = Date.now() - 1000 * (p.age_s || 0);
    const next = p.plan === 'running' || p.plan === 'paused' ? p.next_waypoint : null;
    if (next !== nextIndex) {
      nextIndex = next;
      drawNumbers();
    }
    const ll = [p.lat, p.lon];
    if (!vehicle) {
      vehicle = L.marker(ll, { icon: vehicleIcon(p.heading), keyboard: false }).addTo(map);
      vehicle.getElement().classList.add('airseg-vehicle');
    } else {
      vehicle.setLatLng(ll);
      vehicle.setIcon(vehicleIcon(p.heading));
      vehicle.getElement().classList.add('airseg-vehicle');
    }
    vehicle.getElement().classList.remove('airseg-no-fix');
    vehicle.getElement().dataset.heading = String(p.heading);
    if (addToTrack) {
      trackLine.addLatLng(ll);
    }
    if (!fitted) {
      map.setView(ll, 18);
      fitted = true;
    }
    const parts = [p.lat.toFixed(6) + ', ' + p.lon.toFixed(6), 'heading ' + Math.round(p.heading) + '°',
                   (p.speed || 0).toFixed(1) + ' m/s'];
    if (p.battery_pct != null) {
      parts.push('battery ' + p.battery_pct + ' %');
    }
    document.getElementById('vehicle-text').textContent = parts.join(' · ');
    positionAge = null;
    showAge();
    showProgress();
    publish();
  }

  // Once the last position is older than a couple of seconds, it says how old, and the marker greys.
  function showAge() {
    const age = positionAt == null ? null : Math.floor((Date.now() - positionAt) / 1000);
    const stale = age != null && age >= kStaleSeconds;
    positionAge = stale ? age : null;
    document.getElementById('vehicle-age').textContent = stale ? 'position ' + age + ' s old' : '';
    if (vehicle) {
      vehicle.getElement().classList.toggle('airseg-stale', stale);
    }
  }
  setInterval(() => { showAge(); publish(); }, 1000);

  // A sample without a fix: the vehicle stays where it was last known, greyed, and says so.
  function setNoFix(fix) {
    noFix = true;
    if (vehicle) {
      vehicle.getElement().classList.add('airseg-no-fix');
    }
    const last = lastPosition ? ' · last known ' + lastPosition.lat.toFixed(6) + ', ' +
                                lastPosition.lon.toFixed(6) + ' at ' + lastPosition.t : '';
    document.getElementById('vehicle-text').textContent =
      'no fix (GPS fix type ' + fix.gps_fix + ')' + last;
    showAge();
    publish();
  }

  // Up: its figures. Down: since when, and the last figures greyed (they are history, not the link now).
  function setLink(link) {
    linkState = link;
    const box = document.getElementById('link');
    const up = link && link.link;
    box.className = 'link-' + (up || 'unknown');
    const figures = (l) => {
      const parts = [];
      if (l && l.rtt_ms != null) {
        parts.push('rtt ' + l.rtt_ms + ' ms');
      }
      if (l && l.loss != null) {
        parts.push('loss ' + (100 * l.loss).toFixed(1) + ' %');
      }
      return parts.join(' · ');
    };
    const text = document.getElementById('link-text');
    const last = document.getElementById('link-last');
    if (up === 'up' || up === 'degraded') {
      text.textContent = [up, figures(link)].filter(Boolean).join(' · ');
      last.textContent = '';
    } else if (link && link.down_since) {
      text.textContent = 'down since ' + link.down_since.substring(11, 19);
      const was = figures(link.last);
      last.textContent = was ? 'last: ' + was : '';
    } else {
      text.textContent = (up || 'unknown') + (link && link.note ? ' · ' + link.note : '');
      last.textContent = '';
    }
    publish();
  }

  // Events in plan terms, once per happening (the hub words them: groundside/event_wording.hpp); the debug
  // view lists every event in the vehicle's own words, slot numbers and all.
  function eventItem(e) {
    const li = document.createElement('li');
    li.className = 'airseg-event' + (e.debug ? ' airseg-event-debug' : '') +
                   (e.severity && e.severity !== 'info' ? ' airseg-event-' + e.severity : '');
    const words = debugView && e.raw && e.raw !== e.text && !e.debug ? e.text + ' [' + e.raw + ']'
                : debugView && e.debug ? e.raw || e.text : e.text;
    li.textContent = (e.t ? e.t.substring(11, 19) + ' ' : '') + words;
    return li;
  }

  function addEvent(e) {
    eventLog.push(e);
    if (eventLog.length > 400) {
      eventLog.shift();
    }
    eventCount += 1;
    if (!e.debug || debugView) {
      const list = document.getElementById('events');
      list.insertBefore(eventItem(e), list.firstChild);
      while (list.children.length > 200) {
        list.removeChild(list.lastChild);
      }
    }
    publish();
  }

  function showEvents() {
    const list = document.getElementById('events');
    list.textContent = '';
    eventLog.filter(e => !e.debug || debugView).slice(-200).forEach(e => {
      list.insertBefore(eventItem(e), list.firstChild);
    });
    publish();
  }
  document.getElementById('debug-view').onchange = (ev) => {
    debugView = ev.target.checked;
    showEvents();
  };

  function setControl(on) {
    control = on;
    ['btn-pause', 'btn-resume', 'btn-skip', 'btn-load'].forEach(id => { document.getElementById(id).disabled = !on; });
    document.getElementById('btn-load-label').classList.toggle('disabled', !on);
    document.getElementById('control-note').hidden = on;
  }

  function setBackground(tileUrl) {
    if (background) {
      map.removeLayer(background);
    }
    background = tileUrl ? L.tileLayer(tileUrl, { maxZoom: 20 }) : new Grid();
    background.addTo(map);
  }

  async function command(request) {
    const out = document.getElementById('command-result');
    out.textContent = request.cmd + '…';
    try {
      const r = await fetch('/api/command', {
        method: 'POST',
        headers: { 'Content-Type': 'application/json', 'X-Airseg-Token': token },
        body: JSON.stringify(request)
      });
      const answer = await r.json();
      out.textContent = request.cmd + ': ' + (answer.ok ? 'done' : answer.error);
    } catch (err) {
      out.textContent = request.cmd + ': ' + err;
    }
  }
  document.getElementById('btn-pause').onclick = () => command({ cmd: 'plan.pause' });
  document.getElementById('btn-resume').onclick = () => command({ cmd: 'plan.resume' });
  document.getElementById('btn-skip').onclick = () => {
    const target = window.prompt('Skip to a waypoint number (as numbered on the map) or an element name');
    if (target === null || target.trim() === '') {
      return;
    }
    const t = target.trim();
    // The map numbers waypoints from 1; the vehicle's index counts from 0.
    command(/^[1-9]\d*$/.test(t) ? { cmd: 'plan.skip', index: Number(t) - 1 } : { cmd: 'plan.skip', element: t });
  };
  document.getElementById('btn-load').onchange = async (ev) => {
    const file = ev.target.files[0];
    if (file) {
      command({ cmd: 'plan.load', text: await file.text(), source: file.name });
    }
    ev.target.value = '';
  };

  setBackground('');
  setControl(false);
  // ?debug=1: the debug view from the start (every event as the vehicle sent it).
  const params = new URLSearchParams(location.search);
  if (params.get('debug') === '1') {
    debugView = true;
    document.getElementById('debug-view').checked = true;
  }
  publish();

  // ?for=S: follow the vehicle for S seconds, then keep the picture (a snapshot; no reconnecting).
  const follow = params.get('for');
  const events = new EventSource('/events' + (follow ? '?for=' + encodeURIComponent(follow) : ''));
  events.addEventListener('state', ev => {
    const s = JSON.parse(ev.data);
    token = s.token || '';
    setControl(!!s.control);
    setBackground(s.tile_url);
    drawPlan(s.plan);
    trackLine.setLatLngs(latlngs(s.track));
    if (s.position) {
      setPosition(s.position, false);
    }
    if (s.fix && s.fix.valid === false) {
      setNoFix(s.fix);
    }
    setLink(s.link);
    document.getElementById('events').textContent = '';
    eventCount = 0;
    eventLog = [];
    (s.events || []).forEach(addEvent);
  });
  events.addEventListener('plan', ev => drawPlan(JSON.parse(ev.data)));
  events.addEventListener('position', ev => setPosition(JSON.parse(ev.data), true));
  events.addEventListener('fix', ev => setNoFix(JSON.parse(ev.data)));
  events.addEventListener('link', ev => setLink(JSON.parse(ev.data)));
  events.addEventListener('event', ev => addEvent(JSON.parse(ev.data)));
  events.onerror = () => {
    if (follow) {
      events.close();
      snapshotOver = true;
      publish();
      return;
    }
    setLink({ link: 'down', note: 'no connection to the hub', down_since: linkState && linkState.down_since,
              last: linkState && linkState.link === 'up' ? linkState : linkState && linkState.last });
  };
})();
