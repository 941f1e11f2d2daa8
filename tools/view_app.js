// SPDX-License-Identifier: BSD-3-Clause
/* view_app.js - the script of the page `occmap view` writes (tools/view_page.c inlines it after
 * three.js r147 and its OrbitControls). OCC_MAP holds the map's facts and three node arrays
 * (occupied, free, unknown), each base64 of x[n] y[n] z[n] (keys minus the set's min, kw bytes,
 * little-endian) then level[n]; a node's centre is (key - 2^(depth-1) + 2^level / 2) * res and
 * its edge res * 2^level, as the library's occ_map_key_center(). Each kind is one InstancedMesh
 * of unit cubes; the map frame is ENU (z up). After the first frame the page writes the number
 * of cubes the renderer drew in it into #status (data-drawn): the occupied ones, as free and
 * unknown start hidden (tests/view_check.sh compares it with the map's occupied leaves). */
(function () {
  'use strict';
  var status = document.getElementById('status');

  function fail(msg) {
    status.textContent = 'error: ' + msg;
    status.setAttribute('data-error', msg);
  }

  function bytesOf(b64) {
    var s = atob(b64), u = new Uint8Array(s.length);
    for (var i = 0; i < s.length; i++) u[i] = s.charCodeAt(i);
    return u;
  }

  /* Centres and edges (metres) of one set's nodes. */
  function decode(set, res, depth) {
    var n = set.n, kw = set.kw, u = bytesOf(set.b64), dv = new DataView(u.buffer);
    var half = Math.pow(2, depth - 1), out = {n: n, c: [new Float32Array(n), new Float32Array(n),
      new Float32Array(n)], size: new Float32Array(n)};
    for (var i = 0; i < n; i++) out.size[i] = res * Math.pow(2, u[3 * kw * n + i]);
    for (var a = 0; a < 3; a++) {
      for (i = 0; i < n; i++) {
        var off = (a * n + i) * kw;
        var k = set.min[a] + (kw === 2 ? dv.getUint16(off, true) : dv.getUint32(off, true));
        out.c[a][i] = (k - half) * res + 0.5 * out.size[i];
      }
    }
    return out;
  }

  /* Height colour as octovis draws it: blue (low) through green to red (high). */
  function heightColor(z, zmin, zmax, color) {
    var t = zmax > zmin ? (z - zmin) / (zmax - zmin) : 0.5;
    t = Math.min(1, Math.max(0, t));
    color.setHSL((1 - t) * 0.66, 0.9, 0.5);
  }

  function cubes(nodes, material, zrange) {
    var mesh = new THREE.InstancedMesh(new THREE.BoxGeometry(1, 1, 1), material, Math.max(nodes.n, 1));
    var m = new THREE.Matrix4(), color = new THREE.Color();
    for (var i = 0; i < nodes.n; i++) {
      var s = nodes.size[i];
      m.makeScale(s, s, s);
      m.setPosition(nodes.c[0][i], nodes.c[1][i], nodes.c[2][i]);
      mesh.setMatrixAt(i, m);
      if (zrange) {
        heightColor(nodes.c[2][i], zrange[0], zrange[1], color);
        mesh.setColorAt(i, color);
      }
    }
    mesh.count = nodes.n;
    mesh.instanceMatrix.needsUpdate = true;
    if (mesh.instanceColor) mesh.instanceColor.needsUpdate = true;
    mesh.frustumCulled = false; /* the geometry's bounds are one unit cube, not the instances' */
    return mesh;
  }

  function main() {
    var map = OCC_MAP, res = map.res, depth = map.depth;
    var lo = map.bbox_min, hi = map.bbox_max;
    if (!map.has_known) { lo = [-1, -1, -1]; hi = [1, 1, 1]; }
    var renderer = new THREE.WebGLRenderer({antialias: true, preserveDrawingBuffer: true});
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    renderer.setSize(window.innerWidth, window.innerHeight);
    renderer.setClearColor(0x1b1e23, 1);
    document.getElementById('view').appendChild(renderer.domElement);

    var scene = new THREE.Scene();
    scene.add(new THREE.HemisphereLight(0xffffff, 0x444444, 0.75));
    var sun = new THREE.DirectionalLight(0xffffff, 0.6);
    sun.position.set(0.4, 0.7, 1.0);
    scene.add(sun);

    var occ = cubes(decode(map.occupied, res, depth), new THREE.MeshLambertMaterial(), [lo[2], hi[2]]);
    var free = cubes(decode(map.free, res, depth), new THREE.MeshBasicMaterial(
      {color: 0x55cc66, transparent: true, opacity: 0.06, depthWrite: false}));
    var unknown = cubes(decode(map.unknown, res, depth), new THREE.MeshBasicMaterial(
      {color: 0xb0b0b0, transparent: true, opacity: 0.07, depthWrite: false}));
    free.visible = false;
    unknown.visible = false;
    var box = new THREE.Box3(new THREE.Vector3(lo[0], lo[1], lo[2]), new THREE.Vector3(hi[0], hi[1], hi[2]));
    var bbox = new THREE.Box3Helper(box, 0xffcc33);
    scene.add(occ, free, unknown, bbox);

    var centre = box.getCenter(new THREE.Vector3()), diag = box.getSize(new THREE.Vector3()).length();
    var camera = new THREE.PerspectiveCamera(45, window.innerWidth / window.innerHeight, diag / 1000, diag * 20);
    camera.up.set(0, 0, 1);
    camera.position.set(centre.x - 0.35 * diag, centre.y - 0.55 * diag, centre.z + 0.45 * diag);
    var controls = new THREE.OrbitControls(camera, renderer.domElement);
    controls.target.copy(centre);
    controls.update();

    var drawn = -1;
    function render() {
      renderer.render(scene, camera);
      if (drawn < 0) { /* the first frame shows the occupied cubes only (and the box's lines) */
        drawn = renderer.info.render.triangles / 12;
        status.setAttribute('data-drawn', String(drawn));
        status.setAttribute('data-occupied-leaves', String(map.occupied_leaves));
      }
      status.textContent = occ.count + ' occupied leaves (' + map.free.n + ' free, ' + map.unknown.n +
        ' unknown), ' + res + ' m';
    }
    function toggle(id, obj) {
      var el = document.getElementById(id);
      el.addEventListener('change', function () { obj.visible = el.checked; render(); });
      obj.visible = el.checked;
    }
    toggle('show-occupied', occ);
    toggle('show-free', free);
    toggle('show-unknown', unknown);
    toggle('show-bbox', bbox);
    controls.addEventListener('change', render);
    window.addEventListener('resize', function () {
      camera.aspect = window.innerWidth / window.innerHeight;
      camera.updateProjectionMatrix();
      renderer.setSize(window.innerWidth, window.innerHeight);
      render();
    });
    render();
  }

  try { main(); } catch (e) { fail(String((e && e.message) || e)); }
})();
