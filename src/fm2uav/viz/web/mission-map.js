/* fm2uav mission map: draws a mission map document (fm2uav.viz.mapdata.mission_map)
 * on a Leaflet map, with the lon/lat graticule, the height-above-ground legend and the
 * altitude/ground profile (uPlot). Used by the web app; a self-contained report can
 * inline this file, the vendored libraries and the document.
 *
 *   const layers = FM2Map.renderMission(map, doc);      // L.LayerGroup of the mission
 *   FM2Map.profile(element, doc, {onHover: i => ...});   // the profile chart
 *   FM2Map.graticule(map);                               // lon/lat lines with labels
 */
(function (global) {
  "use strict";

  // colour of a height above ground as a share of the requested height
  // (fm2uav.viz.mapdata.AGL_COLOURS): red at the ground, green at the level, blue above
  const STOPS = [[0.0, [215, 25, 28]], [0.5, [253, 174, 97]], [1.0, [26, 150, 65]],
                 [1.6, [43, 131, 186]]];

  function aglColour(agl, requested) {
    const t = requested ? agl / requested : 1.0;
    if (t <= STOPS[0][0]) return rgb(STOPS[0][1]);
    for (let k = 1; k < STOPS.length; k++) {
      if (t <= STOPS[k][0]) {
        const [a, ca] = STOPS[k - 1], [b, cb] = STOPS[k];
        const u = (t - a) / (b - a);
        return rgb(ca.map((c, i) => c + u * (cb[i] - c)));
      }
    }
    return rgb(STOPS[STOPS.length - 1][1]);
  }
  function rgb(c) { return `rgb(${c.map(v => Math.round(v)).join(",")})`; }

  function feature(doc, kind) { return doc.features.filter(f => f.properties.kind === kind); }

  function fmt(v, unit, nd) {
    return v === null || v === undefined ? "–" : `${Number(v).toFixed(nd ?? 0)} ${unit}`;
  }

  function zoneText(p) {
    const parts = [p.inclusion ? "operating area" : "no-fly zone", p.name || ""];
    const ref = p.reference === "agl" ? "AGL" : "AMSL";
    if (p.floor !== null && p.floor !== undefined) parts.push(`floor ${p.floor} m ${ref}`);
    if (p.ceiling !== null && p.ceiling !== undefined) parts.push(`ceiling ${p.ceiling} m ${ref}`);
    if (p.buffer) parts.push(`buffer ${p.buffer} m`);
    return parts.filter(Boolean).join(" · ");
  }

  /** A short label of a zone for the map: its name and vertical extent. */
  function zoneLabel(p) {
    const name = p.name || (p.inclusion ? "operating area" : "no-fly zone");
    const ref = p.reference === "agl" ? "AGL" : "AMSL";
    const has = v => v !== null && v !== undefined;
    if (!has(p.floor) && !has(p.ceiling)) return `${name}: all heights`;
    const lo = has(p.floor) ? `${p.floor}` : "ground", hi = has(p.ceiling) ? `${p.ceiling}` : "∞";
    return `${name}: ${lo}–${hi} m ${ref}`;
  }

  function escapeHtml(t) {
    return String(t).replace(/[&<>"]/g, c => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;",
                                               '"': "&quot;" })[c]);
  }

  /** Draw one route: by height above ground (colour scale) or in its own colour. */
  function drawRoute(layer, f, renderer) {
    const c = f.geometry.coordinates, p = f.properties, agl = p.agl;
    const ll = c.map(q => [q[1], q[0]]);
    const tip = escapeHtml(p.name || "route");
    // long routes (hundreds of survey bands) thin, without the dark halo
    const weight = c.length > 10000 ? 1.5 : c.length > 3000 ? 3 : 4;
    if (c.length <= 10000) {
      L.polyline(ll, { color: "#000", weight: weight + 3, opacity: 0.3, renderer,
                       interactive: false }).addTo(layer);
    }
    if (p.color || !agl) {
      L.polyline(ll, { color: p.color || "#c0392b", weight: p.color ? weight - 1 : weight,
                       renderer, dashArray: p.dash || null,
                       className: "fm2-route" }).bindTooltip(tip, { sticky: true }).addTo(layer);
      return;
    }
    // segments coloured by height above ground (runs of one colour joined)
    const scale = p.requested_agl || p.agl_scale;
    let run = [ll[0]], colour = aglColour(agl[0], scale);
    const flush = () => L.polyline(run, { color: colour, weight, renderer, className: "fm2-route" })
      .bindTooltip(`${tip} (colour: height above ground)`, { sticky: true }).addTo(layer);
    for (let i = 1; i < c.length; i++) {
      const col = aglColour(0.5 * (agl[i - 1] + agl[i]), scale);
      if (col !== colour && run.length > 1) {
        flush();
        run = [run[run.length - 1]];
      }
      colour = col;
      run.push(ll[i]);
    }
    flush();
  }

  /** Draw the mission on the map; returns the L.LayerGroup (remove it to clear).
   *
   * opts.points: false leaves out the start/goal/via markers; opts.groups: an object that
   * receives one L.LayerGroup per kind of layer, by name (for a layer switcher);
   * opts.zoneLabels: the zones' names and vertical extents written on the map. */
  function renderMission(map, doc, opts) {
    opts = opts || {};
    const group = L.layerGroup();
    const renderer = L.canvas({ padding: 0.5 });
    const groups = opts.groups;
    function grp(name) {
      if (!groups) return group;
      if (!groups[name]) { groups[name] = L.layerGroup(); groups[name].addTo(group); }
      return groups[name];
    }
    const buildings = feature(doc, "building");
    if (buildings.length) {
      L.geoJSON(buildings, {
        renderer, style: () => ({ color: "#2b2b2b", weight: 1, fillColor: "#5f5f66",
                                  fillOpacity: 0.78 }),
        onEachFeature: (f, l) => l.bindTooltip(f.properties.height === null ||
          f.properties.height === undefined ? "obstacle" :
          `building, ${f.properties.height} m above the ground`, { sticky: true }),
      }).addTo(grp(opts.buildingsName || "buildings"));
    }
    for (const f of feature(doc, "photo")) {
      L.geoJSON(f, { renderer, style: () => ({ color: "#6a3d9a", weight: 0.6, opacity: 0.55,
                                                 fillColor: "#cab2d6", fillOpacity: 0.12 }),
                     interactive: false }).addTo(grp("photo footprints"));
    }
    for (const f of feature(doc, "area")) {
      L.geoJSON(f, { style: () => ({ color: "#1f4e9e", weight: 3, fill: false }) })
        .bindTooltip(`survey area, ${(f.properties.area_m2 / 1e4).toFixed(1)} ha`, { sticky: true })
        .addTo(grp("survey area"));
    }
    const bands = feature(doc, "band");
    for (const f of bands) {
      L.geoJSON(f, { renderer, interactive: false, style: () => ({
        color: "#555", weight: bands.length > 60 ? 0.6 : 1, dashArray: "4 4" }) })
        .addTo(grp("bands (planned)"));
    }
    for (const f of feature(doc, "zone")) {
      const p = f.properties;
      const style = p.inclusion
        ? { color: "#1a9641", weight: 2, fill: false, dashArray: "8 4" }
        : { color: "#c0392b", weight: 2, fillColor: "#e74c3c", fillOpacity: 0.18 };
      const layer = L.geoJSON(f, { style: () => style }).bindTooltip(zoneText(p), { sticky: true });
      layer.addTo(grp(p.inclusion ? "operating area" : "no-fly zones"));
      if (opts.zoneLabels) {
        const at = p.center ? [p.center[1], p.center[0]] : layer.getBounds().getCenter();
        L.marker(at, { interactive: false, keyboard: false, icon: L.divIcon({
          className: "fm2-zone-label", html: `<span>${escapeHtml(zoneLabel(p))}</span>`,
          iconSize: null }) })
          .addTo(grp(p.inclusion ? "operating area" : "no-fly zones"));
      }
    }
    for (const f of feature(doc, "fence")) {
      const style = { color: "#ff8c00", weight: 1.5, dashArray: "2 6", fill: false,
                      interactive: false };
      if (f.geometry.type === "Point") {
        const [lon, lat] = f.geometry.coordinates;
        L.circle([lat, lon], Object.assign({ radius: f.properties.radius }, style))
          .addTo(grp("geofence"));
      } else {
        L.geoJSON(f, { style: () => style }).addTo(grp("geofence"));
      }
    }
    for (const f of feature(doc, "extra")) {
      const p = f.properties, st = Object.assign({ color: "#333", weight: 2 }, p.style || {});
      const layer = L.geoJSON(f, { style: () => st, pointToLayer: (g, at) =>
        L.circleMarker(at, Object.assign({ radius: 5, fillOpacity: 0.9 }, st)) });
      if (p.label) layer.bindTooltip(escapeHtml(p.label), { sticky: true });
      layer.addTo(grp(p.layer || "more"));
    }
    // the safe returns (fm2uav.viz.mapdata.return_features): the ways back under the route
    for (const f of feature(doc, "return")) {
      const p = f.properties;
      L.geoJSON(f, { renderer, style: () => ({ color: "#5b6b8c", weight: 1.5, opacity: 0.7,
                                                 dashArray: "3 4", className: "fm2-return" }) })
        .bindTooltip(`way back from waypoint ${p.waypoint} to ${escapeHtml(p.to)}: ` +
                     `${fmt(p.length_m / 1000, "km", 2)}, ${fmt(p.time_s / 60, "min", 1)}` +
                     (p.battery_share !== undefined
                       ? ` (${(100 * p.battery_share).toFixed(0)} % of the endurance)` : ""),
                     { sticky: true })
        .addTo(grp("ways back"));
    }
    for (const f of feature(doc, "pnr-return")) {
      L.geoJSON(f, { style: () => ({ color: "#8e44ad", weight: 3, dashArray: "8 5",
                                     className: "fm2-pnr-return" }) })
        .bindTooltip(`way back from the point of no return: ${fmt(f.properties.time_s / 60, "min", 1)}`,
                     { sticky: true })
        .addTo(grp("ways back"));
    }
    const amsl = !(doc.summary && doc.summary.amsl === false);
    // routes: the one coloured by height above ground first, the others (flown tracks,
    // followers, thinner) over it
    const routes = feature(doc, "route");
    routes.sort((a, b) => (a.properties.color ? 1 : 0) - (b.properties.color ? 1 : 0));
    for (const f of routes) drawRoute(grp(f.properties.name || "route"), f, renderer);
    const items = feature(doc, "item");
    const small = items.length > 60;
    const itemMarkers = [];
    items.forEach((f, k) => {
      const p = f.properties, [lon, lat] = f.geometry.coordinates;
      const size = small ? 16 : 22;
      const width = Math.max(size, (small ? 6 : 7) * String(p.seq).length + (small ? 5 : 8));
      // the first, the last and every 10th keep their number where markers crowd
      const major = k === 0 || k === items.length - 1 || p.seq % 10 === 0;
      const icon = L.divIcon({ className: "fm2-item" + (small ? " fm2-item-small" : "") +
                                 (major ? " fm2-item-major" : ""),
                               iconSize: [width, size], html: `<span>${p.seq}</span>` });
      const frame = p.frame === null || p.frame === undefined ? "" : ` (frame ${p.frame})`;
      const marker = L.marker([lat, lon], { icon, keyboard: false, interactive: true,
                                            zIndexOffset: major ? 0 : -500, major });
      itemMarkers.push(marker);
      marker
        .bindTooltip(`${p.seq} ${escapeHtml(p.command)}${p.label ? " (" + escapeHtml(p.label) + ")" : ""}<br>` +
                     `alt ${fmt(p.alt, "m", 1)}${frame} · ${fmt(p.alt_amsl, "m", 1)} ` +
                     `${amsl ? "AMSL" : "above the flat ground"} · ${fmt(p.agl, "m", 1)} above ground`)
        .addTo(grp("waypoints"));
    });
    for (const f of feature(doc, "rally")) {
      const p = f.properties, [lon, lat] = f.geometry.coordinates;
      L.marker([lat, lon], { icon: L.divIcon({ className: "fm2-rally", iconSize: [22, 22],
                                               html: "<span>R</span>" }) })
        .bindTooltip(`${escapeHtml(p.name)}${p.chosen_by ? " (chosen by the " + escapeHtml(p.chosen_by) + ")" : ""}`)
        .addTo(grp("rally points"));
    }
    for (const f of feature(doc, "pnr")) {
      const p = f.properties, [lon, lat] = f.geometry.coordinates;
      L.marker([lat, lon], { icon: L.divIcon({ className: "fm2-pnr", iconSize: [26, 26],
                                               html: "<span>PNR</span>" }) })
        .bindTooltip(`point of no return: ${fmt(p.distance_m / 1000, "km", 2)} along the route, ` +
                     `${fmt(p.t_mission_s / 60, "min", 1)} into the mission` +
                     (p.passed_before_end ? " — the mission passes it before its end" : ""))
        .addTo(grp("point of no return"));
    }
    if (opts.points !== false) {
      for (const kind of ["start", "goal", "via"]) {
        for (const f of feature(doc, kind)) {
          const [lon, lat] = f.geometry.coordinates;
          L.circleMarker([lat, lon], { radius: 6, color: "#fff", weight: 2, fillOpacity: 1,
                                       fillColor: kind === "start" ? "#1a9641" :
                                         kind === "goal" ? "#c0392b" : "#2b6cb0" })
            .bindTooltip(escapeHtml(f.properties.name), { permanent: !!opts.pointLabels,
                                                          direction: "right" })
            .addTo(grp("start / goal"));
        }
      }
    }
    group.itemMarkers = itemMarkers;
    group.addTo(map);
    return group;
  }

  /** Show only the waypoint markers that keep minPx apart on screen (the first, the last
   * and every 10th first), again after each zoom; returns the update function. */
  function declutter(map, markers, minPx) {
    const cell = minPx || 22;
    const order = markers.slice().sort((a, b) => (b.options.major ? 1 : 0) -
                                                  (a.options.major ? 1 : 0));
    function update() {
      const taken = new Set();
      for (const m of order) {
        const p = map.latLngToContainerPoint(m.getLatLng());
        const i = Math.floor(p.x / cell), j = Math.floor(p.y / cell);
        let free = true;
        for (let di = -1; di <= 1 && free; di++) {
          for (let dj = -1; dj <= 1 && free; dj++) {
            if (taken.has(`${i + di},${j + dj}`)) free = false;
          }
        }
        if (free) taken.add(`${i},${j}`);
        const el = m.getElement();
        if (el) el.style.display = free ? "" : "none";
      }
    }
    map.on("zoomend overlayadd", update);
    update();
    return update;
  }

  /** The legend of the route colours (an L.Control). */
  function aglLegend(requested, title) {
    const ctl = L.control({ position: "bottomright" });
    ctl.onAdd = function () {
      const div = L.DomUtil.create("div", "fm2-legend");
      const req = requested || 1;
      title = title || "height above ground";
      const stops = [0, 0.25, 0.5, 0.75, 1.0, 1.3, 1.6];
      const grad = stops.map(s => `${aglColour(s * req, req)} ${100 * s / 1.6}%`).join(",");
      div.innerHTML = `<div class="fm2-legend-title">${escapeHtml(title)}</div>` +
        `<div class="fm2-legend-bar" style="background:linear-gradient(to right,${grad})"></div>` +
        `<div class="fm2-legend-ticks"><span>0 m</span><span>${Math.round(req / 2)}</span>` +
        `<span>${Math.round(req)} m</span><span>${Math.round(1.6 * req)}</span></div>`;
      return div;
    };
    return ctl;
  }

  /** Lon/lat lines at a round step for the zoom, labelled at the map's edges. */
  function graticule(map) {
    const layer = L.layerGroup().addTo(map);
    const steps = [10, 5, 2, 1, 0.5, 0.2, 0.1, 0.05, 0.02, 0.01, 0.005, 0.002, 0.001,
                   0.0005, 0.0002, 0.0001];
    // "3.765° W", as the figures and plan.png write them (no sign to misread)
    const hemi = (v, nd, pos, neg) => {
      const t = Math.abs(v).toFixed(nd);
      return `${t}° ${v < 0 && Number(t) !== 0 ? neg : pos}`;
    };
    function redraw() {
      layer.clearLayers();
      const b = map.getBounds(), span = Math.max(b.getEast() - b.getWest(),
                                                 b.getNorth() - b.getSouth());
      const step = steps.find(s => span / s >= 3) || steps[steps.length - 1];
      const nd = Math.max(0, Math.ceil(-Math.log10(step)));
      const style = { color: "#334", weight: 0.7, opacity: 0.45, interactive: false,
                      dashArray: "3 4" };
      for (let lon = Math.ceil(b.getWest() / step) * step; lon <= b.getEast(); lon += step) {
        L.polyline([[b.getSouth(), lon], [b.getNorth(), lon]], style).addTo(layer);
        L.marker([b.getNorth(), lon], { interactive: false, icon: L.divIcon({
          className: "fm2-grat fm2-grat-lon", html: hemi(lon, nd, "E", "W"), iconSize: null }) })
          .addTo(layer);
      }
      for (let lat = Math.ceil(b.getSouth() / step) * step; lat <= b.getNorth(); lat += step) {
        L.polyline([[lat, b.getWest()], [lat, b.getEast()]], style).addTo(layer);
        L.marker([lat, b.getWest()], { interactive: false, icon: L.divIcon({
          className: "fm2-grat fm2-grat-lat", html: hemi(lat, nd, "N", "S"), iconSize: null }) })
          .addTo(layer);
      }
    }
    map.on("moveend zoomend resize", redraw);
    if (map._loaded) redraw(); else map.whenReady(redraw);
    return layer;
  }

  /** Altitude and ground along the route (uPlot); returns the chart. */
  function profile(el, doc, opts) {
    opts = opts || {};
    const route = feature(doc, "route")[0];
    if (!route || typeof uPlot === "undefined") return null;
    const c = route.geometry.coordinates, p = route.properties;
    const x = p.distance.map(d => d / 1000);
    const alt = c.map(q => q[2]), ground = p.ground;
    const level = p.requested_agl ? ground.map(g => g + p.requested_agl) : ground.map(() => null);
    // waypoints on the profile: nearest route point of each item
    const wp = x.map(() => null);
    for (const f of feature(doc, "item")) {
      const [lon, lat] = f.geometry.coordinates;
      let best = 0, bd = Infinity;
      for (let i = 0; i < c.length; i++) {
        const d = (c[i][0] - lon) ** 2 + (c[i][1] - lat) ** 2;
        if (d < bd) { bd = d; best = i; }
      }
      wp[best] = f.properties.alt_amsl;
    }
    el.innerHTML = "";
    const width = Math.max(300, el.clientWidth || 600);
    const chart = new uPlot({
      width, height: opts.height || 190,
      scales: { x: { time: false } },
      axes: [{ label: "distance along the route [km]", size: 40 },
             { label: p.amsl === false ? "height above the flat ground [m] (altitude AMSL unknown)"
                                       : "altitude AMSL [m]", size: 60 }],
      cursor: { drag: { x: false, y: false } },
      legend: { live: true },
      series: [
        { label: "km", value: (u, v) => v === null ? "–" : v.toFixed(2) },
        { label: "ground", stroke: "#8b5a2b", fill: "rgba(139,90,43,0.25)", width: 1.5,
          value: (u, v) => v === null ? "–" : v.toFixed(1) + " m" },
        { label: `requested ${p.requested_agl ?? "–"} m AGL`, stroke: "#1a9641", width: 1,
          dash: [6, 4], value: (u, v) => v === null ? "–" : v.toFixed(1) + " m" },
        { label: "flight altitude", stroke: "#1f4e9e", width: 2,
          value: (u, v) => v === null ? "–" : v.toFixed(1) + " m" },
        { label: "waypoints", stroke: "#111", width: 0, points: { show: true, size: 7,
          fill: "#fff" }, paths: () => null,
          value: (u, v) => v === null ? "–" : v.toFixed(1) + " m" },
      ],
      hooks: { setCursor: [u => { if (opts.onHover) opts.onHover(u.cursor.idx); }] },
    }, [x, ground, level, alt, wp], el);
    return chart;
  }

  global.FM2Map = { renderMission, aglColour, aglLegend, graticule, profile, zoneText,
                    zoneLabel, declutter };
})(window);
