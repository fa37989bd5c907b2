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
      vehicle: lastPosition ? { lat: lastPosition.lat, lon: lastPosition.lon, heading: lastPosition.heading } : null,
      link: linkState,
      events: eventCount,
      control: control,
      no_fix: noFix
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

  function drawPlan(plan) {
    planLayer.clearLayers();
    Object.keys(counts).forEach(k => { counts[k] = 0; });
    planName = plan && plan.name ? plan.name : null;
    document.getElementById('plan-name').textContent = planName ? planName : 'no plan';
    const bounds = L.latLngBounds([]);
    const mainRoute = [];
    ((plan && plan.elements) || []).forEach((e, i) => {
      const pts = latlngs(e.points);
      // Detached blocks run only when jumped to: they are drawn, but not joined to the main route.
      const route = String(e.path || '').startsWith('plan.blocks') ? [] : mainRoute;
      const title = (e.name ? e.name + ' — ' : '') + e.kind + ' ' + e.path;
      counts.elements += 1;
      pts.forEach(p => bounds.extend(p));
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
    if (plan && plan.truncated) {
      addEvent({ text: 'the plan is drawn in part: it has more points than a map answer carries' });
    }
    if (bounds.isValid()) {
      map.fitBounds(bounds.pad(0.15));
      fitted = true;
    }
    publish();
  }

  function vehicleIcon(heading) {
    const svg = '<svg width="28" height="28" viewBox="-14 -14 28 28" style="transform: rotate(' + (heading || 0) +
                'deg)"><path d="M0,-12 L8,10 L0,5 L-8,10 Z" fill="#ff8c00" stroke="#000" stroke-width="1.5"/></svg>';
    return L.divIcon({ className: 'airseg-vehicle-icon', html: svg, iconSize: [28, 28], iconAnchor: [14, 14] });
  }

  function setPosition(p, addToTrack) {
    lastPosition = p;
    noFix = false;
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
    publish();
  }

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
    publish();
  }

  function setLink(link) {
    linkState = link;
    const box = document.getElementById('link');
    const up = link && link.link;
    box.className = 'link-' + (up || 'unknown');
    const parts = [up || 'unknown'];
    if (link && link.rtt_ms != null) {
      parts.push('rtt ' + link.rtt_ms + ' ms');
    }
    if (link && link.loss != null) {
      parts.push('loss ' + (100 * link.loss).toFixed(1) + ' %');
    }
    document.getElementById('link-text').textContent = parts.join(' · ');
    publish();
  }

  function addEvent(e) {
    const li = document.createElement('li');
    li.className = 'airseg-event';
    li.textContent = (e.t ? e.t.substring(11, 19) + ' ' : '') + e.text;
    const list = document.getElementById('events');
    list.insertBefore(li, list.firstChild);
    while (list.children.length > 200) {
      list.removeChild(list.lastChild);
    }
    eventCount += 1;
    publish();
  }

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
    const target = window.prompt('Skip to a waypoint number or an element name');
    if (target === null || target.trim() === '') {
      return;
    }
    const t = target.trim();
    command(/^\d+$/.test(t) ? { cmd: 'plan.skip', index: Number(t) } : { cmd: 'plan.skip', element: t });
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
  publish();

  // ?for=S: follow the vehicle for S seconds, then keep the picture (a snapshot; no reconnecting).
  const follow = new URLSearchParams(location.search).get('for');
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
      return;
    }
    setLink({ link: 'down', note: 'no connection to the hub' });
  };
})();
