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

  /** Draw the mission on the map; returns the L.LayerGroup (remove it to clear). */
  function renderMission(map, doc, opts) {
    opts = opts || {};
    const group = L.layerGroup();
    const renderer = L.canvas({ padding: 0.5 });
    for (const f of feature(doc, "fence")) {
      const style = { color: "#ff8c00", weight: 1.5, dashArray: "2 6", fill: false,
                      interactive: false };
      if (f.geometry.type === "Point") {
        const [lon, lat] = f.geometry.coordinates;
        L.circle([lat, lon], Object.assign({ radius: f.properties.radius }, style)).addTo(group);
      } else {
        L.geoJSON(f, { style: () => style }).addTo(group);
      }
    }
    for (const f of feature(doc, "photo")) {
      L.geoJSON(f, { renderer, style: () => ({ color: "#6a3d9a", weight: 0.6, opacity: 0.55,
                                                 fillColor: "#cab2d6", fillOpacity: 0.12 }),
                     interactive: false }).addTo(group);
    }
    for (const f of feature(doc, "area")) {
      L.geoJSON(f, { style: () => ({ color: "#1f4e9e", weight: 3, fill: false }) })
        .bindTooltip(`survey area, ${(f.properties.area_m2 / 1e4).toFixed(1)} ha`, { sticky: true })
        .addTo(group);
    }
    for (const f of feature(doc, "band")) {
      L.geoJSON(f, { renderer, interactive: false, style: () => ({ color: "#555", weight: 1,
                                                                  dashArray: "4 4" }) })
        .addTo(group);
    }
    for (const f of feature(doc, "zone")) {
      const p = f.properties;
      const style = p.inclusion
        ? { color: "#1a9641", weight: 2, fill: false, dashArray: "8 4" }
        : { color: "#c0392b", weight: 2, fillColor: "#e74c3c", fillOpacity: 0.18 };
      L.geoJSON(f, { style: () => style })
        .bindTooltip(zoneText(p), { sticky: true }).addTo(group);
    }
    const route = feature(doc, "route")[0];
    if (route) {
      const c = route.geometry.coordinates, agl = route.properties.agl;
      const req = route.properties.requested_agl;
      // halo, then segments coloured by height above ground (runs of one colour joined)
      L.polyline(c.map(p => [p[1], p[0]]), { color: "#000", weight: 7, opacity: 0.35,
                                              renderer, interactive: false }).addTo(group);
      let run = [[c[0][1], c[0][0]]], colour = aglColour(agl[0], req);
      for (let i = 1; i < c.length; i++) {
        const col = aglColour(0.5 * (agl[i - 1] + agl[i]), req);
        if (col !== colour && run.length > 1) {
          L.polyline(run, { color: colour, weight: 4, renderer, className: "fm2-route" })
            .addTo(group);
          run = [run[run.length - 1]];
        }
        colour = col;
        run.push([c[i][1], c[i][0]]);
      }
      L.polyline(run, { color: colour, weight: 4, renderer, className: "fm2-route" })
        .addTo(group);
    }
    for (const f of feature(doc, "item")) {
      const p = f.properties, [lon, lat] = f.geometry.coordinates;
      const icon = L.divIcon({ className: "fm2-item", iconSize: [22, 22],
                               html: `<span>${p.seq}</span>` });
      L.marker([lat, lon], { icon, keyboard: false, interactive: true, zIndexOffset: -500 })
        .bindTooltip(`${p.seq} ${p.command}${p.label ? " (" + p.label + ")" : ""}<br>` +
                     `alt ${fmt(p.alt, "m", 1)} (frame ${p.frame}) · ${fmt(p.alt_amsl, "m", 1)} ` +
                     `AMSL · ${fmt(p.agl, "m", 1)} above ground`)
        .addTo(group);
    }
    if (opts.points !== false) {
      for (const kind of ["start", "goal", "via"]) {
        for (const f of feature(doc, kind)) {
          const [lon, lat] = f.geometry.coordinates;
          L.circleMarker([lat, lon], { radius: 5, color: "#fff", weight: 2, fillOpacity: 1,
                                       fillColor: kind === "start" ? "#1a9641" :
                                         kind === "goal" ? "#c0392b" : "#2b6cb0" })
            .bindTooltip(f.properties.name).addTo(group);
        }
      }
    }
    group.addTo(map);
    return group;
  }

  /** The legend of the route colours (an L.Control). */
  function aglLegend(requested) {
    const ctl = L.control({ position: "bottomright" });
    ctl.onAdd = function () {
      const div = L.DomUtil.create("div", "fm2-legend");
      const req = requested || 1;
      const stops = [0, 0.25, 0.5, 0.75, 1.0, 1.3, 1.6];
      const grad = stops.map(s => `${aglColour(s * req, req)} ${100 * s / 1.6}%`).join(",");
      div.innerHTML = `<div class="fm2-legend-title">height above ground</div>` +
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
          className: "fm2-grat fm2-grat-lon", html: `${lon.toFixed(nd)}°`, iconSize: null }) })
          .addTo(layer);
      }
      for (let lat = Math.ceil(b.getSouth() / step) * step; lat <= b.getNorth(); lat += step) {
        L.polyline([[lat, b.getWest()], [lat, b.getEast()]], style).addTo(layer);
        L.marker([lat, b.getWest()], { interactive: false, icon: L.divIcon({
          className: "fm2-grat fm2-grat-lat", html: `${lat.toFixed(nd)}°`, iconSize: null }) })
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
             { label: "altitude AMSL [m]", size: 60 }],
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

  global.FM2Map = { renderMission, aglColour, aglLegend, graticule, profile, zoneText };
})(window);
