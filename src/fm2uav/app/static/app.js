/* fm2uav app page: edits a mission document (the mission-file schema of fm2uav.io.mission)
 * on the map, runs jobs on the server (world check, planning) and shows their results.
 * The server plans nothing itself: a planning job is `fm2uav run` on this document. */
(function () {
  "use strict";
  const $ = id => document.getElementById(id);
  const S = {
    base: {}, dem: [], buildings: null, fileZones: [], points: { start: null, goal: null, via: [] },
    zones: [], tool: null, terrain: null, job: null, result: null, resultLayer: null,
    legend: null, choices: {}, hover: null, stale: false, worldOk: false,
  };
  window.fm2app = S;   // for tests and the curious

  // ------------------------------------------------------------------ map
  // whole zoom levels: at fractional ones the browser leaves hairline gaps between tiles
  const map = L.map("map", { zoomControl: true, zoomSnap: 1, fadeAnimation: false })
    .setView([20, 0], 2);
  S.map = map;
  L.control.scale({ metric: true, imperial: false, maxWidth: 220, position: "bottomleft" })
    .addTo(map);
  const layerCtl = L.control.layers({}, {}, { position: "topright", collapsed: true }).addTo(map);
  const online = L.tileLayer("https://tile.openstreetmap.org/{z}/{x}/{y}.png", {
    maxZoom: 19, attribution: "© OpenStreetMap contributors" });
  layerCtl.addOverlay(online, "online map (OpenStreetMap; needs internet)");
  const grat = FM2Map.graticule(map);
  layerCtl.addOverlay(grat, "lon/lat grid");
  const pointLayer = L.layerGroup().addTo(map);
  const zoneLayer = L.featureGroup().addTo(map);
  map.createPane("terrain").style.zIndex = 250;

  const readout = L.control({ position: "bottomleft" });
  readout.onAdd = () => { const d = L.DomUtil.create("div", "fm2-readout"); d.id = "readout";
                          d.textContent = "lon –  lat –  ground –"; return d; };
  readout.addTo(map);
  let hTimer = null, hSeq = 0;
  map.on("mousemove", e => {
    const { lat, lng } = e.latlng;
    const base = `lon ${lng.toFixed(6)}  lat ${lat.toFixed(6)}`;
    const el = $("readout");
    el.dataset.base = base;
    el.textContent = `${base}  ground ${el.dataset.ground || "–"}`;
    clearTimeout(hTimer);
    if (!S.terrain) return;
    hTimer = setTimeout(async () => {
      const seq = ++hSeq;
      const r = await fetch(`/api/terrain/${S.terrain.id}/height?lon=${lng}&lat=${lat}`);
      if (!r.ok || seq !== hSeq) return;
      const j = await r.json();
      el.dataset.ground = j.ground_m === null ? "off the DEM" : `${j.ground_m.toFixed(1)} m`;
      el.textContent = `${el.dataset.base}  ground ${el.dataset.ground}`;
    }, 120);
  });

  // ------------------------------------------------------------------ helpers
  async function api(path, body) {
    const r = await fetch(path, body === undefined ? {} : {
      method: "POST", headers: { "Content-Type": "application/json" },
      body: JSON.stringify(body) });
    const j = await r.json().catch(() => ({ error: `${r.status} ${r.statusText}` }));
    if (!r.ok) throw new Error(j.error || j.detail || `${r.status} ${r.statusText}`);
    return j;
  }
  function showError(msg) {
    const e = $("error");
    if (!msg) { e.hidden = true; e.textContent = ""; return; }
    e.hidden = false;
    e.textContent = msg.startsWith("error:") || msg.startsWith("internal error:")
      ? msg : `error: ${msg}`;
  }
  function progress(fraction, text) {
    $("progress-fill").style.width = `${Math.round(100 * fraction)}%`;
    $("progress-text").textContent = text;
  }
  function num(id) {
    const v = $(id).value.trim();
    return v === "" ? undefined : Number(v);
  }
  function setNum(id, v) { if (v !== undefined && v !== null) $(id).value = v; }
  function esc(s) { return String(s).replace(/[&<>"]/g, c => ({ "&": "&amp;", "<": "&lt;",
                                                               ">": "&gt;", '"': "&quot;" })[c]); }
  function markStale() {
    if (S.result && !S.stale) {
      S.stale = true;
      $("cards").insertAdjacentHTML("afterbegin",
        '<div class="card bad" id="stale"><div class="v">changed</div><div class="k">since this plan: plan again</div></div>');
    }
  }

  // ------------------------------------------------------------------ jobs
  function runJob(body, onDone) {
    showError(null);
    return api("/api/jobs", body).then(job => new Promise(resolve => {
      S.job = job; $("btn-cancel").disabled = false; $("btn-plan").disabled = true;
      progress(0, `${job.kind}: queued`);
      const es = new EventSource(`/api/jobs/${job.id}/events`);
      es.onmessage = ev => {
        const j = JSON.parse(ev.data);
        S.job = j;
        const pct = Math.round(100 * j.fraction);
        progress(j.fraction, `${j.kind}: ${j.stage} — ${pct} %` +
                 (j.elapsed_s !== null ? `, ${j.elapsed_s.toFixed(1)} s` : ""));
        if (j.state === "done" || j.state === "error" || j.state === "cancelled") {
          es.close();
          $("btn-cancel").disabled = true; $("btn-plan").disabled = false;
          if (j.state === "error") {
            showError(j.error);
            progress(0, `${j.kind}: failed`);
          } else if (j.state === "cancelled") {
            progress(0, `${j.kind}: cancelled`);
          } else {
            progress(1, `${j.kind}: done in ${j.elapsed_s.toFixed(1)} s` +
                     (j.warnings.length ? ` — ${j.warnings.length} warning(s)` : ""));
            if (j.warnings.length) showError(j.warnings.map(w => `warning: ${w}`).join("\n"));
            Promise.resolve(onDone(j)).catch(err => showError(err.message))
              .then(() => resolve(j));
            return;
          }
          resolve(j);
        }
      };
      es.onerror = () => { /* the browser reconnects; the job state is kept server-side */ };
    })).catch(err => { showError(err.message); });
  }
  $("btn-cancel").onclick = async () => {
    if (S.job) await api(`/api/jobs/${S.job.id}/cancel`, {});
  };

  // ------------------------------------------------------------------ world
  function worldDoc() {
    const w = Object.assign({}, S.base.world || {});
    delete w.scenario; delete w.seed;
    if (S.dem.length) w.dem = S.dem.length === 1 ? S.dem[0] : S.dem.slice(); else delete w.dem;
    if (S.buildings) w.buildings = S.buildings; else delete w.buildings;
    for (const k of ["cell_size", "sea_level"]) {
      const v = num(`w-${k}`);
      if (v === undefined) delete w[k]; else w[k] = v;
    }
    return w;
  }
  function renderWorldList() {
    $("dem-list").innerHTML = S.dem.map((p, i) =>
      `<li>${esc(p)} <button data-i="${i}" class="rm-dem" title="remove">×</button></li>`).join("");
    for (const b of document.querySelectorAll(".rm-dem")) {
      b.onclick = () => { S.dem.splice(Number(b.dataset.i), 1); renderWorldList(); loadWorld(); };
    }
    $("buildings-name").textContent = S.buildings || "none";
  }
  let buildingsLayer = null, contourLayer = null, terrainLayer = null;
  async function loadWorld() {
    markStale();
    S.worldOk = false;
    if (!S.dem.length && !S.buildings) { $("world-info").textContent = "no world loaded"; return; }
    await runJob({ kind: "world", world: worldDoc(), agl: num("p-agl") }, async j => {
      S.worldOk = true;
      const r = j.result;
      $("world-info").innerHTML = "<table>" + Object.entries(r.rows).map(([k, v]) =>
        `<tr><td>${esc(k)}</td><td>${esc(v)}</td></tr>`).join("") + "</table>";
      if (buildingsLayer) { map.removeLayer(buildingsLayer); layerCtl.removeLayer(buildingsLayer); }
      buildingsLayer = null;
      if (r.buildings) {
        buildingsLayer = L.geoJSON(r.buildings, { style: () => ({ color: "#333", weight: 1,
          fillColor: "#777", fillOpacity: 0.55 }) })
          .bindTooltip(l => `building, ${l.feature.properties.height ?? "?"} m`, { sticky: true })
          .addTo(map);
        layerCtl.addOverlay(buildingsLayer, "buildings");
      }
      await showTerrain(r.bounds);
    });
  }
  async function showTerrain(bounds) {
    for (const l of [terrainLayer, contourLayer]) {
      if (l) { map.removeLayer(l); layerCtl.removeLayer(l); }
    }
    terrainLayer = contourLayer = null; S.terrain = null;
    if (S.dem.length) {
      try {
        S.terrain = await api("/api/terrain", { dem: S.dem });
      } catch (err) { showError(err.message); }
    }
    if (S.terrain) {
      const [w, s, e, n] = S.terrain.bounds;
      terrainLayer = L.tileLayer(`/api/terrain/${S.terrain.id}/{z}/{x}/{y}.png`, {
        pane: "terrain", maxZoom: 20, maxNativeZoom: 18, bounds: [[s, w], [n, e]],
        attribution: `DEM: ${S.dem.map(p => p.split("/").pop()).join(", ")}` }).addTo(map);
      S.terrainLayer = terrainLayer;
      layerCtl.addBaseLayer(terrainLayer, "DEM shaded relief");
      const c = await api(`/api/terrain/${S.terrain.id}/contours`);
      contourLayer = L.geoJSON(c, { interactive: false, style: f => ({
        color: "#7a5230", weight: f.properties.index ? 1.3 : 0.6,
        opacity: f.properties.index ? 0.8 : 0.5 }) }).addTo(map);
      contourLayer.eachLayer(l => {
        if (!l.feature.properties.index) return;
        const ln = l.getLatLngs()[0];
        if (ln && ln.length) {
          const mid = ln[Math.floor(ln.length / 2)];
          L.marker(mid, { interactive: false, icon: L.divIcon({
            className: "fm2-contour-label", iconSize: null,
            html: `${l.feature.properties.elevation} m` }) }).addTo(contourLayer);
        }
      });
      layerCtl.addOverlay(contourLayer, `contours every ${c.interval} m`);
    }
    const b = bounds || (S.terrain && S.terrain.bounds);
    if (b && !S.points.start && !S.points.goal) map.fitBounds([[b[1], b[0]], [b[3], b[2]]]);
  }
  $("btn-dem-add").onclick = () => {
    const p = $("dem-path").value.trim();
    if (p) { S.dem.push(p); $("dem-path").value = ""; renderWorldList(); loadWorld(); }
  };
  $("btn-buildings-add").onclick = () => {
    S.buildings = $("buildings-path").value.trim() || null; renderWorldList(); loadWorld();
  };
  async function upload(input) {
    const f = input.files[0];
    if (!f) return null;
    const fd = new FormData(); fd.append("file", f);
    const r = await fetch("/api/upload", { method: "POST", body: fd });
    const j = await r.json();
    input.value = "";
    if (!r.ok) { showError(j.error || j.detail); return null; }
    return j.path;
  }
  $("dem-upload").onchange = async e => {
    const p = await upload(e.target); if (p) { S.dem.push(p); renderWorldList(); loadWorld(); }
  };
  $("buildings-upload").onchange = async e => {
    const p = await upload(e.target); if (p) { S.buildings = p; renderWorldList(); loadWorld(); }
  };
  for (const id of ["w-cell_size", "w-sea_level"]) $(id).onchange = loadWorld;

  // ------------------------------------------------------------------ points
  function pointIcon(kind, label) {
    return L.divIcon({ className: `fm2-point ${kind}`, iconSize: [24, 24], html: label });
  }
  function renderPoints() {
    pointLayer.clearLayers();
    const list = [];
    const add = (kind, p, label, remove) => {
      const m = L.marker([p.lat, p.lon], { draggable: true, icon: pointIcon(kind, label),
                                          title: `${kind} ${label}`, autoPan: true })
        .addTo(pointLayer);
      m.on("dragend", () => { const ll = m.getLatLng(); p.lat = ll.lat; p.lon = ll.lng;
                              renderPoints(); markStale(); });
      m.on("contextmenu", () => { remove(); renderPoints(); markStale(); });
      list.push(`<li>${kind} ${kind === "via" ? label : ""}: ${p.lon.toFixed(6)}, ${p.lat.toFixed(6)}</li>`);
    };
    const P = S.points;
    if (P.start) add("start", P.start, "S", () => { P.start = null; });
    P.via.forEach((v, i) => add("via", v, String(i + 1), () => { P.via.splice(i, 1); }));
    if (P.goal) add("goal", P.goal, "G", () => { P.goal = null; });
    $("point-list").innerHTML = list.join("");
  }
  function setTool(tool) {
    S.tool = S.tool === tool ? null : tool;
    for (const b of document.querySelectorAll("[data-tool]")) {
      b.classList.toggle("active", b.dataset.tool === S.tool);
    }
    $("map").classList.toggle("picking", !!S.tool);
  }
  for (const b of document.querySelectorAll("[data-tool]")) b.onclick = () => setTool(b.dataset.tool);
  $("btn-clear-points").onclick = () => {
    S.points = { start: null, goal: null, via: [] }; renderPoints(); markStale();
  };
  map.on("click", e => {
    if (!S.tool || map.pm.globalDrawModeEnabled()) return;
    const p = { lon: e.latlng.lng, lat: e.latlng.lat };
    if (S.tool === "via") S.points.via.push(p);
    else { S.points[S.tool] = p; setTool(S.tool); }
    renderPoints(); markStale();
  });
  $("return-to-start").onchange = markStale;

  // ------------------------------------------------------------------ zones
  map.pm.setGlobalOptions({ snappable: false, continueDrawing: false,
                            pathOptions: { color: "#c0392b", fillColor: "#e74c3c",
                                           fillOpacity: 0.2, weight: 2 } });
  $("tool-zone-polygon").onclick = () => {
    setTool(null); S.drawing = "zone"; map.pm.enableDraw("Polygon", { finishOn: null });
  };
  $("tool-zone-circle").onclick = () => {
    setTool(null); S.drawing = "zone"; map.pm.enableDraw("Circle");
  };
  let zoneIds = 0;
  function addZone(layer, props) {
    const z = Object.assign({ id: ++zoneIds, layer, name: `zone ${zoneIds}`, floor: null,
                              ceiling: null, reference: "amsl", buffer: 0 }, props || {});
    layer.addTo(zoneLayer);
    layer.on("pm:edit", markStale);
    layer.on("click", () => { layer.pm.toggleEdit(); });
    S.zones.push(z); renderZones(); markStale();
    return z;
  }
  map.on("pm:create", e => {
    map.removeLayer(e.layer);
    if (S.drawing === "area") setArea(e.layer); else addZone(e.layer);
    S.drawing = null;
  });
  const areaLayer = L.featureGroup().addTo(map);
  function setArea(layer) {
    areaLayer.clearLayers();
    S.area = layer;
    if (layer) {
      layer.setStyle({ color: "#1f4e9e", weight: 3, fillColor: "#2b83ba", fillOpacity: 0.08,
                       dashArray: null });
      layer.addTo(areaLayer);
      layer.on("pm:edit", () => { markStale(); areaInfo(); });
      layer.on("click", () => layer.pm.toggleEdit());
    }
    areaInfo(); markStale();
  }
  function areaInfo() {
    if (!S.area) { $("area-info").textContent = "no area drawn"; return; }
    const ring = S.area.getLatLngs()[0];
    // planar area on the local tangent plane (display only; the plan measures in the map's CRS)
    const R = 6371008.8, lat0 = ring[0].lat * Math.PI / 180;
    const xy = ring.map(p => [R * p.lng * Math.PI / 180 * Math.cos(lat0), R * p.lat * Math.PI / 180]);
    let a = 0;
    for (let i = 0; i < xy.length; i++) {
      const [x1, y1] = xy[i], [x2, y2] = xy[(i + 1) % xy.length];
      a += x1 * y2 - x2 * y1;
    }
    $("area-info").textContent = `area: ${ring.length} corners, about ${(Math.abs(a) / 2e4).toFixed(1)} ha`;
  }
  $("tool-area").onclick = () => {
    setTool(null); S.drawing = "area";
    map.pm.enableDraw("Polygon", { finishOn: null, pathOptions: { color: "#1f4e9e" } });
  };
  $("btn-area-clear").onclick = () => setArea(null);
  $("c-preset").onchange = () => { $("c-camera").value = $("c-preset").value; markStale(); };
  $("btn-cover").onclick = async () => {
    if (!S.dem.length && !S.buildings) { showError("load a world first: add a DEM (World panel)"); return; }
    if (!S.area) { showError("draw the survey area first (Survey panel: Draw area)"); return; }
    const cam = $("c-camera").value.trim();
    const cover = { agl: num("p-agl") };
    for (const k of ["min_agl", "max_agl", "saturation_distance"]) {
      const v = num(`p-${k}`); if (v !== undefined) cover[k] = v;
    }
    if (cam) {
      const v = cam.split(/[ ,]+/).filter(Boolean).map(Number);
      if (v.length !== 5 || v.some(x => !(x > 0))) {
        showError("camera: give 5 numbers sensor_width_mm,sensor_height_mm,focal_mm,image_width_px,image_height_px (e.g. 13.2,8.8,8.8,5472,3648)");
        return;
      }
      cover.camera = v;
      for (const k of ["side_overlap", "front_overlap", "trigger_distance"]) {
        const x = num(`c-${k}`); if (x !== undefined) cover[k] = x;
      }
    } else {
      const d = num("c-spacing");
      if (d === undefined) { showError("give the band spacing [m] or choose a camera (Survey panel)"); return; }
      cover.spacing = d;
      const t = num("c-trigger_distance"); if (t !== undefined) cover.trigger_distance = t;
    }
    const area = S.area.getLatLngs()[0].map(p => [p.lng, p.lat]);
    await runJob({ kind: "cover", mission: missionDoc(), area, cover }, j => showResult(j));
  };
  function renderZones() {
    const refs = S.choices.reference || ["amsl", "agl"];
    const items = S.zones.map(z => `<li data-id="${z.id}">
      <div class="zhead"><input class="z-name" value="${esc(z.name)}" aria-label="zone name">
      <span>${z.layer instanceof L.Circle ? "circle " + Math.round(z.layer.getRadius()) + " m" : "polygon"}</span>
      <button class="z-rm" title="delete zone">×</button></div>
      <div class="grid2">
        <label>floor [m]<input class="z-floor" type="number" step="any" value="${z.floor ?? ""}" placeholder="ground"></label>
        <label>ceiling [m]<input class="z-ceiling" type="number" step="any" value="${z.ceiling ?? ""}" placeholder="none"></label>
        <label>buffer [m]<input class="z-buffer" type="number" min="0" step="any" value="${z.buffer ?? 0}"></label>
        <label>heights from<select class="z-reference">${refs.map(r =>
          `<option ${r === z.reference ? "selected" : ""}>${r}</option>`).join("")}</select></label>
      </div></li>`);
    const files = S.fileZones.map((f, i) => `<li data-file="${i}"><div class="zhead">
      <span class="file">file: ${esc(typeof f === "string" ? f : f.file || "inline zone (metres)")}</span>
      <button class="zf-rm" title="remove">×</button></div></li>`);
    $("zone-list").innerHTML = items.concat(files).join("");
    for (const li of document.querySelectorAll("#zone-list li[data-id]")) {
      const z = S.zones.find(q => q.id === Number(li.dataset.id));
      const val = sel => li.querySelector(sel);
      const upd = () => {
        z.name = val(".z-name").value;
        const f = val(".z-floor").value, c = val(".z-ceiling").value, b = val(".z-buffer").value;
        z.floor = f === "" ? null : Number(f); z.ceiling = c === "" ? null : Number(c);
        z.buffer = b === "" ? 0 : Number(b); z.reference = val(".z-reference").value;
        markStale();
      };
      for (const inp of li.querySelectorAll("input, select")) inp.onchange = upd;
      val(".z-rm").onclick = () => {
        zoneLayer.removeLayer(z.layer); S.zones = S.zones.filter(q => q !== z);
        renderZones(); markStale();
      };
    }
    for (const li of document.querySelectorAll("#zone-list li[data-file]")) {
      li.querySelector(".zf-rm").onclick = () => {
        S.fileZones.splice(Number(li.dataset.file), 1); renderZones(); markStale();
      };
    }
  }
  $("zones-upload").onchange = async e => {
    const p = await upload(e.target); if (p) { S.fileZones.push(p); renderZones(); markStale(); }
  };
  function zoneEntry(z) {
    const e = {};
    if (z.layer instanceof L.Circle) {
      const c = z.layer.getLatLng();
      e.circle = { center: [c.lng, c.lat], radius: z.layer.getRadius() };
    } else {
      const ring = z.layer.getLatLngs()[0];
      e.polygon = ring.map(p => [p.lng, p.lat]);
    }
    e.lonlat = true;
    if (z.name) e.name = z.name;
    if (z.floor !== null && z.floor !== undefined) e.floor = z.floor;
    if (z.ceiling !== null && z.ceiling !== undefined) e.ceiling = z.ceiling;
    if (z.reference && z.reference !== "amsl") e.reference = z.reference;
    if (z.buffer) e.buffer = z.buffer;
    return e;
  }

  // ------------------------------------------------------------------ the mission document
  function section(base, fields) {
    const out = Object.assign({}, base || {});
    for (const [key, id, kind] of fields) {
      let v;
      if (kind === "check") v = $(id).checked ? true : undefined;
      else if (kind === "select") v = $(id).value || undefined;
      else v = num(id);
      if (v === undefined) delete out[key]; else out[key] = v;
    }
    return out;
  }
  function missionDoc() {
    const b = JSON.parse(JSON.stringify(S.base || {}));
    const d = { version: 1, name: $("mission-name").value.trim() || "mission" };
    if (b.description) d.description = b.description;
    d.world = worldDoc();
    const agl = num("p-agl");
    const pt = p => ({ lon: p.lon, lat: p.lat, agl });
    if (S.points.start) d.start = pt(S.points.start); else if (b.start) d.start = b.start;
    if (S.points.goal) d.goal = pt(S.points.goal); else if (b.goal) d.goal = b.goal;
    if (S.points.via.length) d.via = S.points.via.map(pt);
    if ($("return-to-start").checked) d.return = true;
    d.planner = section(b.planner, [["agl", "p-agl"], ["min_agl", "p-min_agl"],
                                    ["max_agl", "p-max_agl"],
                                    ["saturation_distance", "p-saturation_distance"]]);
    const zones = S.fileZones.concat(S.zones.map(zoneEntry));
    if (zones.length) d.no_fly_zones = zones;
    if (b.operating_area) d.operating_area = b.operating_area;
    d.airframe = section(b.airframe, [["type", "a-type", "select"],
                                      ["firmware", "a-firmware", "select"],
                                      ["cruise_speed", "a-cruise_speed"],
                                      ["hover_speed", "a-hover_speed"],
                                      ["endurance", "a-endurance"], ["reserve", "a-reserve"]]);
    d.outputs = section(b.outputs, [["frame", "o-frame", "select"], ["end", "o-end", "select"],
                                    ["thin_tolerance", "o-thin_tolerance"],
                                    ["speed_changes", "o-speed_changes", "check"]]);
    for (const k of ["airframe", "outputs"]) if (!Object.keys(d[k]).length) delete d[k];
    return d;
  }
  S.missionDoc = missionDoc;

  // ------------------------------------------------------------------ planning
  $("btn-plan").onclick = async () => {
    if (!S.dem.length && !S.buildings) { showError("load a world first: add a DEM (World panel)"); return; }
    const doc = missionDoc();
    if (!doc.start || !doc.goal) {
      showError("click a start and a goal on the map first (Route panel: Start, then Goal)");
      return;
    }
    await runJob({ kind: "plan", mission: doc }, j => showResult(j));
  };

  function card(v, k, bad) {
    return `<div class="card${bad ? " bad" : ""}"><div class="v">${esc(v)}</div><div class="k">${esc(k)}</div></div>`;
  }
  function showResult(job) {
    const r = job.result, doc = r.map, s = doc.summary;
    S.result = Object.assign({ job: job.id }, r); S.stale = false;
    if (S.flown) { map.removeLayer(S.flown); S.flown = null; }
    $("check-info").innerHTML = "";
    if (S.resultLayer) map.removeLayer(S.resultLayer);
    S.resultLayer = FM2Map.renderMission(map, doc, { points: false });
    pointLayer.eachLayer(m => m.setZIndexOffset(1000));
    if (S.legend) S.legend.remove();
    S.legend = FM2Map.aglLegend(s.requested_agl_m).addTo(map);
    const mins = s.flight_time_s / 60;
    const low = s.requested_agl_m !== null && s.min_agl_m < 0.5 * s.requested_agl_m;
    const survey = s.photos !== undefined ? [
      card(`${(s.area_m2 / 1e4).toFixed(1)} ha`, `area, ${(100 * s.coverage).toFixed(1)} % covered`),
      card(`${s.bands} bands`, `${s.spacing_m} m apart, ${s.angle_deg}°`),
      card(`${s.photos} photos`, s.gsd_cm_per_px ? `every ${s.trigger_distance_m} m, ${s.gsd_cm_per_px} cm/px` : `every ${s.trigger_distance_m} m`),
    ] : [];
    $("cards").innerHTML = [
      ...survey,
      card(`${(s.length_m / 1000).toFixed(2)} km`, "route length"),
      card(`${Math.floor(mins)} min ${Math.round((mins % 1) * 60)} s`, "flight time"),
      card(`${s.items} items`, `${s.waypoints} waypoints · ${s.firmware} ${s.vehicle}`),
      card(`${s.min_agl_m} – ${s.max_agl_m} m`, `above ground (asked ${s.requested_agl_m ?? "–"} m)`, low),
      card(s.nearest_zone_m === null ? "no zones" : `${s.nearest_zone_m} m`,
           s.nearest_zone_m === null ? "no-fly zones" : `nearest no-fly zone${s.zone_entries ? ", ENTERED" : ""}`,
           s.zone_entries > 0),
      card(`${s.frame} (${s.mav_frame})`, `altitude frame · end ${s.end}`),
    ].join("");
    const order = ["mission.plan", "mission.waypoints", "path.kml", "path.kmz", "path.geojson",
                   "report.html", "plan.png", "coverage.html", "coverage.png", "bands.png",
                   "path.csv", "zigzag.csv", "summary.json"];
    const names = order.filter(n => r.files.includes(n));
    $("downloads").innerHTML = names.map(n =>
      `<a href="/api/jobs/${job.id}/files/${n}" download="${n}" id="dl-${n.replace(".", "-")}">${n}</a>`)
      .join("") + (job.kind === "plan" ? `<a href="/api/jobs/${job.id}/mission.yaml" download="mission.yaml" id="dl-mission-yaml">mission.yaml</a>` : "");
    $("command").innerHTML = r.command ? `same files from the command line:<br><code>${esc(r.command)}</code>` : "";
    $("rows").innerHTML = Object.entries(doc.rows).map(([k, v]) =>
      `<tr><td>${esc(k)}</td><td>${esc(v)}</td></tr>`).join("") +
      s.warnings.map(w => `<tr><td>warning</td><td>${esc(w)}</td></tr>`).join("");
    $("results").hidden = false;
    map.invalidateSize();
    const route = doc.features.find(f => f.properties.kind === "route");
    FM2Map.profile($("profile"), doc, { onHover: i => {
      if (S.hover) { map.removeLayer(S.hover); S.hover = null; }
      if (i === null || i === undefined || !route) return;
      const c = route.geometry.coordinates[i];
      S.hover = L.circleMarker([c[1], c[0]], { radius: 7, color: "#000", weight: 2,
        fillColor: "#ffeb3b", fillOpacity: 1 }).addTo(map);
    } });
    const bb = doc.bbox;
    map.fitBounds([[bb[1], bb[0]], [bb[3], bb[2]]], { padding: [40, 40] });
  }

  // ------------------------------------------------------------------ check
  $("btn-check").onclick = async () => {
    if (!S.result) { showError("plan or cover first: the check flies the last planned path"); return; }
    await runJob({ kind: "check", job: S.result.job, airframe: $("check-airframe").value }, j => {
      const r = j.result;
      if (S.flown) map.removeLayer(S.flown);
      S.flown = L.geoJSON(r.flown, { style: () => ({ color: "#111", weight: 2, dashArray: "6 5" }) })
        .bindTooltip(`flown by the ${r.flown.properties.airframe} (simulated)`, { sticky: true })
        .addTo(map);
      $("check-info").innerHTML = `<div class="card${r.feasible ? "" : " bad"}" id="check-verdict">` +
        `<div class="v">${r.feasible ? "FLYABLE" : "NOT FLYABLE"}</div><div class="k">${esc(r.reason)}</div></div>` +
        "<table>" + Object.entries(r.rows).map(([k, v]) =>
          `<tr><td>${esc(k)}</td><td>${esc(v)}</td></tr>`).join("") + "</table>";
    });
  };

  // ------------------------------------------------------------------ save
  $("btn-save").onclick = async () => {
    try {
      const r = await api("/api/mission/save", { mission: missionDoc(), path: $("save-path").value });
      $("save-info").innerHTML = `saved <span class="file" id="saved-path">${esc(r.path)}</span><br>` +
        `<code>${esc(r.command)}</code>`;
      showError(null);
    } catch (err) { showError(err.message); }
  };

  // ------------------------------------------------------------------ start-up
  function fill(id, options, value) {
    $(id).innerHTML = options.map(o => `<option ${o === value ? "selected" : ""}>${o}</option>`).join("");
  }
  async function init() {
    const s = await api("/api/session");
    S.base = s.mission || {}; S.choices = s.choices;
    const b = S.base, w = b.world || {};
    $("save-path").value = s.mission_path;
    $("mission-name").value = b.name || "mission";
    S.dem = w.dem === undefined || w.dem === null ? [] : (Array.isArray(w.dem) ? w.dem.slice() : [w.dem]);
    S.buildings = w.buildings || null;
    setNum("w-cell_size", w.cell_size); setNum("w-sea_level", w.sea_level);
    const p = b.planner || {};
    for (const k of ["agl", "min_agl", "max_agl", "saturation_distance"]) setNum(`p-${k}`, p[k]);
    const a = b.airframe || {}, o = b.outputs || {};
    $("check-airframe").innerHTML = Object.entries(s.choices.airframes).map(([k, v]) =>
      `<option value="${k}" ${k === "arducopter" ? "selected" : ""}>${esc(v)}</option>`).join("");
    fill("a-type", s.choices.vehicle, a.type || "multirotor");
    fill("a-firmware", s.choices.firmware, a.firmware || "px4");
    fill("o-frame", s.choices.frame, o.frame || "auto");
    fill("o-end", s.choices.end, o.end || "auto");
    for (const k of ["cruise_speed", "hover_speed", "endurance", "reserve"]) setNum(`a-${k}`, a[k]);
    setNum("o-thin_tolerance", o.thin_tolerance);
    $("o-speed_changes").checked = !!o.speed_changes;
    $("return-to-start").checked = !!b.return;
    const ll = q => q && typeof q === "object" && !Array.isArray(q) && q.lon !== undefined
      ? { lon: q.lon, lat: q.lat } : null;
    S.points.start = ll(b.start); S.points.goal = ll(b.goal);
    S.points.via = (b.via || []).map(ll).filter(Boolean);
    if (S.points.start) delete S.base.start;
    if (S.points.goal) delete S.base.goal;
    for (const z of b.no_fly_zones || []) {
      if (z && z.lonlat && z.polygon) {
        addZone(L.polygon(z.polygon.map(q => [q[1], q[0]]), map.pm.getGlobalOptions().pathOptions), z);
      } else if (z && z.lonlat && z.circle) {
        addZone(L.circle([z.circle.center[1], z.circle.center[0]],
                         Object.assign({ radius: z.circle.radius }, map.pm.getGlobalOptions().pathOptions)), z);
      } else S.fileZones.push(z);
    }
    for (const z of S.zones) { delete z.polygon; delete z.circle; delete z.lonlat; }
    renderWorldList(); renderPoints(); renderZones(); areaInfo();
    for (const id of ["p-agl", "p-min_agl", "p-max_agl", "p-saturation_distance", "a-type",
                      "a-firmware", "a-cruise_speed", "a-hover_speed", "a-endurance",
                      "a-reserve", "o-frame", "o-end", "o-thin_tolerance", "o-speed_changes",
                      "mission-name", "c-camera", "c-spacing", "c-side_overlap",
                      "c-front_overlap", "c-trigger_distance"]) {
      $(id).addEventListener("change", markStale);
    }
    S.ready = true;
    await loadWorld();
    S.loaded = true;
  }
  init().catch(err => showError(err.message));
})();
