/* fm2uav report map: the map of a self-contained report.html (fm2uav.viz.reportmap).
 *
 * Reads the map document from <script type="application/json" id="fm2uav-map-data">
 * (fm2uav.viz.mapdata: routes, waypoints, zones, buildings, survey, extra layers and the
 * world's shaded relief as an image placed by its lon/lat corners) and draws it into
 * #fm2uav-map with mission-map.js: no tile server, nothing fetched. When it is drawn,
 * window.fm2report = {map, doc, groups, ready: true}.
 */
(function () {
  "use strict";
  if (document.readyState === "loading") {   // the page beside the map is parsed first
    document.addEventListener("DOMContentLoaded", draw);
  } else {
    draw();
  }

  function draw() {
  const el = document.getElementById("fm2uav-map");
  const data = document.getElementById("fm2uav-map-data");
  if (!el || !data || typeof L === "undefined") return;
  const doc = JSON.parse(data.textContent);
  // the zoom buttons go bottom right (added below): top left they hid the lat/lon labels
  const map = L.map(el, { zoomSnap: 0.25, zoomDelta: 0.5, attributionControl: false,
                          preferCanvas: true, scrollWheelZoom: true, zoomControl: false });
  const groups = {};
  if (doc.terrain) {
    const [w, s, e, n] = doc.terrain.bounds;
    groups[doc.terrain.kind === "terrain" ? "terrain (shaded relief)" : "ground"] =
      L.imageOverlay(doc.terrain.url, [[s, w], [n, e]], { interactive: false }).addTo(map);
  }
  const mission = FM2Map.renderMission(map, doc, { groups, zoneLabels: true, pointLabels: false,
                                   buildingsName: doc.buildings_name || "buildings" });
  // the layer switcher doubles as the legend: a swatch of each layer's colour
  const swatch = {
    "no-fly zones": "#e74c3c", "operating area": "#1a9641", "geofence": "#ff8c00",
    "buildings": "#5f5f66", "obstacles": "#5f5f66", "survey area": "#1f4e9e",
    "bands (planned)": "#555", "photo footprints": "#cab2d6", "waypoints": "#1f4e9e",
    "start / goal": "#1a9641",
  };
  const colourOf = {};
  for (const f of doc.features) {
    const p = f.properties;
    if (p.kind === "route") colourOf[p.name || "route"] = p.color || (p.agl ? "agl" : "#c0392b");
    if (p.kind === "extra") colourOf[p.layer || "more"] = (p.style || {}).color || "#333";
  }
  const named = {};
  for (const [name, layer] of Object.entries(groups)) {
    const c = colourOf[name] || swatch[name];
    const sw = c === "agl"
      ? '<span class="fm2-sw fm2-sw-agl"></span>'
      : c ? `<span class="fm2-sw" style="background:${c}"></span>` : "";
    named[`${sw}${name.replace(/[&<>]/g, "")}`] = layer;
  }
  const switcher = L.control.layers(null, named, { collapsed: false, position: "topright" })
    .addTo(map);
  const host = document.getElementById("fm2uav-layers");   // beside the map, as its legend
  if (host) host.appendChild(switcher.getContainer());
  L.control.scale({ metric: true, imperial: false, maxWidth: 200, position: "bottomleft" })
    .addTo(map);
  const main = doc.features.find(f => f.properties.kind === "route" && f.properties.agl &&
                                      !f.properties.color);
  if (main) {
    const p = main.properties;
    FM2Map.aglLegend(p.requested_agl || p.agl_scale, p.requested_agl
      ? `height above ground (requested ${p.requested_agl} m)` : "height above ground")
      .addTo(map);
  }
  L.control.zoom({ position: "bottomright" }).addTo(map);   // stacked above the legend
  // cursor position
  const readout = L.control({ position: "bottomleft" });
  readout.onAdd = () => {
    const d = L.DomUtil.create("div", "fm2-readout");
    d.textContent = "lon, lat";
    map.on("mousemove", e => {
      d.textContent = `${e.latlng.lng.toFixed(5)}°, ${e.latlng.lat.toFixed(5)}°`;
    });
    return d;
  };
  readout.addTo(map);
  const [w, s, e, n] = doc.view || doc.bbox;
  const fit = () => map.fitBounds([[s, w], [n, e]], { padding: [28, 28] });
  fit();
  FM2Map.graticule(map);
  // the page lays out further while the figures below load: follow the map's size, and
  // frame the mission again once everything has loaded
  let touched = false;
  map.on("zoomstart movestart", e => { if (e.hard !== true && window.fm2report) touched = true; });
  if (typeof ResizeObserver !== "undefined") {
    new ResizeObserver(() => map.invalidateSize()).observe(el);
  }
  const done = () => {
    map.invalidateSize();
    if (!touched) fit();
    FM2Map.declutter(map, mission.itemMarkers, 24);
    window.fm2report = { map, doc, groups, ready: true };
  };
  if (document.readyState === "complete") done();
  else window.addEventListener("load", done);
  }
})();
