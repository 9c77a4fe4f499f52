// The page of `primseg view`: the mesh coloured by the clusters of a level, sliders over the
// number of clusters and the tolerance (cuts made here, in linear time), the fitted primitives,
// the error curve, the details of a clicked cluster and, on pages written with --regularize, the
// relations of the level (relations.js).
//
// `?test` in the URL selects the test mode: unlit, no antialiasing, each cluster drawn in the
// colour (i + 1) as 24-bit RGB, i its index in the cut, so that a test can count clusters in
// the pixels. window.primseg is the page's programmatic interface (tests, other tools).

import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { readPageData } from './data.js';
import { Tree, TYPE_NAMES } from './hierarchy.js';
import { clusterErrors, facePlane, primitiveSurface } from './primitives.js';
import { ErrorPlot } from './plot.js';
import { BorderLines } from './borders.js';
import { createOverlays } from './hooks.js';
import { LevelRelations, RELATION_MEANINGS } from './relations.js';
import './skeleton.js';

const testMode = new URLSearchParams(location.search).has('test');
const $ = (id) => document.getElementById(id);

// Types drawn in "colour by type" mode, indexed as include/primseg/primitive.hpp.
const TYPE_COLORS = [[120, 150, 200], [235, 150, 60], [90, 190, 110], [190, 110, 210], [220, 80, 90]];
// Beyond this many clusters the primitives are not drawn (too many to read anyway).
const MAX_DRAWN_PRIMITIVES = 2000;
// Points per cluster used to shape a drawn primitive (extents, hull).
const MAX_SHAPE_POINTS = 20000;

function hslToRgb(h, s, l) {
  const k = (n) => (n + h * 12) % 12;
  const a = s * Math.min(l, 1 - l);
  const f = (n) => l - a * Math.max(-1, Math.min(k(n) - 3, 9 - k(n), 1));
  return [Math.round(f(0) * 255), Math.round(f(8) * 255), Math.round(f(4) * 255)];
}

/** A colour for a cluster from its representative face, stable across levels. */
function clusterColor(seed) {
  let h = Math.imul(seed ^ 0x9e3779b9, 0x85ebca6b);
  h = Math.imul(h ^ (h >>> 13), 0xc2b2ae35);
  h ^= h >>> 16;
  const hue = (h & 0xffff) / 65536;
  const saturation = 0.55 + ((h >>> 16) & 0xff) / 255 * 0.35;
  const lightness = 0.45 + ((h >>> 24) & 0xff) / 255 * 0.2;
  return hslToRgb(hue, saturation, lightness);
}

const format = (x) => x === 0 ? '0' : (Math.abs(x) >= 1e4 || (Math.abs(x) < 1e-3 && x !== 0) ? x.toExponential(4) : x.toPrecision(6));
const formatVector = (v) => '(' + v.map(format).join(', ') + ')';

class Viewer {
  constructor(data) {
    this.data = data;
    this.header = data.header;
    this.tree = new Tree(data);
    this.relations = data.relations ? new LevelRelations(data, this.tree) : null;
    this.colorMode = 'cluster';
    this.selected = -1;
    // The relation whose clusters stand out (-1: none): the one under the pointer, else the
    // one clicked (pinned).
    this.emphasized = this.pinned = -1;
    this.stepTimes = [];
    this.setUpScene();
    this.setUpControls();
    this.overlays = createOverlays({
      header: this.header, data, tree: this.tree, scene: this.scene, camera: this.camera,
      canvas: this.renderer.domElement, geometry: this.geometry, drawOrder: this.drawOrder,
      requestRender: () => this.render(),
    });
    this.skeleton = this.overlays.find((overlay) => overlay.name === 'skeleton') ?? null;
    this.setClusters(this.header.initialClusters);
  }

  setUpScene() {
    const canvas = $('view');
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: !testMode, preserveDrawingBuffer: testMode });
    this.renderer.setPixelRatio(testMode ? 1 : window.devicePixelRatio);
    // Colours are written as they should appear: no colour-space conversion (and, in test mode,
    // pixels equal to the cluster codes).
    this.renderer.outputColorSpace = THREE.LinearSRGBColorSpace;
    this.renderer.setClearColor(testMode ? new THREE.Color(0, 0, 0)
      : new THREE.Color().setRGB(0x1d / 255, 0x20 / 255, 0x26 / 255, THREE.LinearSRGBColorSpace));
    this.scene = new THREE.Scene();

    const { positions, triangles, faceOfTriangle } = this.data;
    const T = triangles.length / 3, F = this.tree.faceCount, leafStart = this.tree.leafStart;
    // Triangles are drawn in the tree's leaf order: the triangles of any cluster of any level are
    // one range of the buffers (a step fills ranges). drawOrder[slot] = triangle; the triangles
    // of the leaves from position p on start at slot slotStart[p].
    const slotStart = (this.slotStart = new Uint32Array(F + 1));
    const leafOf = (t) => leafStart[faceOfTriangle ? faceOfTriangle[t] : t];
    for (let t = 0; t < T; ++t) ++slotStart[leafOf(t) + 1];
    for (let p = 0; p < F; ++p) slotStart[p + 1] += slotStart[p];
    const next = slotStart.slice(0, F), drawOrder = (this.drawOrder = new Uint32Array(T));
    for (let t = 0; t < T; ++t) drawOrder[next[leafOf(t)]++] = t;
    // Unshared corners: each triangle has its own colour (flat per-cluster colouring).
    const corners = new Float32Array(T * 9);
    for (let slot = 0; slot < T; ++slot)
      for (let k = 0; k < 3; ++k) {
        const v = 3 * triangles[3 * drawOrder[slot] + k], i = 9 * slot + 3 * k;
        corners[i] = positions[v];
        corners[i + 1] = positions[v + 1];
        corners[i + 2] = positions[v + 2];
      }
    this.geometry = new THREE.BufferGeometry();
    this.geometry.setAttribute('position', new THREE.BufferAttribute(corners, 3));
    // RGBA bytes per corner, written as one 32-bit word (little-endian: R first) per corner.
    this.colors = new Uint8Array(T * 12);
    this.cornerColors = new Uint32Array(this.colors.buffer);
    this.colorAttribute = new THREE.BufferAttribute(this.colors, 4, true);
    this.colorAttribute.setUsage(THREE.DynamicDrawUsage);
    this.geometry.setAttribute('color', this.colorAttribute);
    this.geometry.computeBoundingSphere();
    const material = testMode
      ? new THREE.MeshBasicMaterial({ vertexColors: true, side: THREE.DoubleSide })
      : new THREE.MeshLambertMaterial({ vertexColors: true, flatShading: true, side: THREE.DoubleSide,
        polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1 });
    this.mesh = new THREE.Mesh(this.geometry, material);
    this.scene.add(this.mesh);
    this.wireframe = new THREE.Mesh(this.geometry,
      new THREE.MeshBasicMaterial({ color: 0x000000, wireframe: true, transparent: true, opacity: 0.35 }));
    this.wireframe.visible = false;
    this.scene.add(this.wireframe);
    // White in test mode: no cluster's code up to 2^24 - 1 clusters.
    this.borderLines = new BorderLines(this.data, this.geometry, this.drawOrder, testMode ? 0xffffff : 0x15171c);
    this.scene.add(this.borderLines.lines);

    const sphere = this.geometry.boundingSphere;
    this.radius = sphere.radius > 0 ? sphere.radius : 1;
    this.camera = new THREE.PerspectiveCamera(35, 1, this.radius / 100, this.radius * 100);
    this.scene.add(this.camera);
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x404050, 1.2));
    const light = new THREE.DirectionalLight(0xffffff, 1.6);
    light.position.set(0.5, 1, 2);
    this.camera.add(light);
    this.controls = new OrbitControls(this.camera, canvas);
    this.controls.addEventListener('change', () => this.render());
    this.setView([1, 0.8, 1.4]);
    window.addEventListener('resize', () => this.resize());
    this.resize();
  }

  /** Looks at the whole mesh from `direction` (from the centre towards the camera). */
  setView(direction) {
    const d = new THREE.Vector3(...direction).normalize();
    const center = this.geometry.boundingSphere.center;
    const distance = this.radius / Math.sin(THREE.MathUtils.degToRad(35 / 2)) * 1.05;
    this.camera.position.copy(center).addScaledVector(d, distance);
    this.camera.up.set(Math.abs(d.y) > 0.99 ? 1 : 0, Math.abs(d.y) > 0.99 ? 0 : 1, 0);
    this.controls.target.copy(center);
    this.controls.update();
    this.render();
  }

  resize() {
    const canvas = this.renderer.domElement;
    this.renderer.setSize(canvas.clientWidth, canvas.clientHeight, false);
    this.camera.aspect = canvas.clientWidth / Math.max(1, canvas.clientHeight);
    this.camera.updateProjectionMatrix();
    this.render();
  }

  render() {
    if (!this.renderer || this.deferRender) return;
    this.borderLines?.refresh();
    this.renderer.render(this.scene, this.camera);
  }

  setUpControls() {
    const F = this.tree.faceCount;
    $('title').textContent = `${this.header.name}: ${F.toLocaleString('en')} faces`;
    document.title = `${this.header.name} - primseg`;
    const slider = $('clusters-slider'), input = $('clusters-input');
    input.max = String(F);
    // The slider is logarithmic in K: a step means the same relative change at every level.
    const logF = Math.log(Math.max(2, F));
    slider.addEventListener('input', () =>
      this.setClusters(Math.round(Math.exp((slider.valueAsNumber / 1000) * logF))));
    input.addEventListener('change', () => this.setClusters(input.valueAsNumber));
    this.sliderOf = (K) => Math.round((Math.log(K) / logF) * 1000);

    // Tolerance: logarithmic between the smallest and the largest positive RMS estimate; 0 at
    // the left end.
    let low = Infinity, high = 0;
    for (const r of this.data.rms)
      if (r > 0) {
        low = Math.min(low, r);
        high = Math.max(high, r);
      }
    if (!(high > 0)) [low, high] = [1e-9, 1];
    this.toleranceRange = [Math.log(low), Math.log(high * 1.001)];
    const tolerance = $('tolerance-slider');
    tolerance.addEventListener('input', () => {
      const s = tolerance.valueAsNumber / 1000;
      const [a, b] = this.toleranceRange;
      this.setTolerance(s === 0 ? 0 : Math.exp(a + s * (b - a)));
    });

    $('color-mode').addEventListener('change', (event) => {
      this.colorMode = event.target.value;
      this.recolor();
    });
    $('show-primitives').addEventListener('change', () => this.updatePrimitives());
    $('show-borders').addEventListener('change', (event) => {
      this.borderLines.setVisible(event.target.checked, this.cut);
      this.render();
    });
    $('show-wireframe').addEventListener('change', (event) => {
      this.wireframe.visible = event.target.checked;
      this.render();
    });

    if (this.relations) {
      $('relations-row').style.display = '';
      $('relations-range').textContent = `up to ${this.relations.last.toLocaleString('en')} clusters`;
    }
    this.plot = new ErrorPlot($('plot'), this.tree.errorCurve, this.tree.minClusters, (K) => this.setClusters(K));
    if (Array.isArray(this.header.levels)) this.showLevels(this.header.levels, this.header.autoLevel);

    // A click (not a drag) selects the cluster under the pointer.
    const canvas = this.renderer.domElement;
    let down = null;
    canvas.addEventListener('pointerdown', (event) => (down = [event.clientX, event.clientY]));
    canvas.addEventListener('pointerup', (event) => {
      if (down && Math.hypot(event.clientX - down[0], event.clientY - down[1]) < 4)
        this.pick(event.clientX, event.clientY);
      down = null;
    });
  }

  /**
   * Ticks the automatic levels on the plot and offers them as buttons, by increasing K.
   * @param levels [{clusters, score, mergeScore, rms}] (or plain K); chosen: the automatic
   *     level's K
   */
  showLevels(levels, chosen) {
    const marks = levels.map((level) => (typeof level === 'number' ? { clusters: level } : level))
      .sort((a, b) => a.clusters - b.clusters);
    this.plot.setLevels(marks, chosen);
    const box = $('levels');
    box.textContent = '';
    for (const { clusters, score, mergeScore } of marks) {
      const button = document.createElement('button');
      button.textContent = String(clusters);
      button.dataset.clusters = String(clusters);
      button.title = (clusters === chosen ? 'the automatic level (--clusters auto)' : 'a candidate level') +
        (score !== undefined ? `: the error curve jumps ${format(score)}x at the next merge` : '') +
        (mergeScore !== undefined ? `, which makes a cluster ${format(mergeScore)}x the level's RMS` : '');
      if (clusters === chosen) button.classList.add('chosen');
      button.addEventListener('click', () => this.setClusters(clusters));
      box.appendChild(button);
    }
    $('levels-row').style.display = marks.length ? '' : 'none';
  }

  setClusters(K) {
    if (!Number.isFinite(K)) return;
    const start = performance.now();
    this.tolerance = null;
    this.apply(this.tree.cutByCount(K), start);
  }

  setTolerance(tolerance) {
    const start = performance.now();
    this.tolerance = tolerance;
    this.apply(this.tree.cutByTolerance(tolerance), start);
  }

  // A step: the cut (already made since `start`), the colours and panels, then one frame. The
  // page's own work is timed apart from the frame, which the GPU draws.
  apply(cut, start) {
    this.deferRender = true;
    this.cut = cut;
    this.selected = -1;
    this.levelRelations = this.relationsOf(cut);
    this.emphasized = this.pinned = -1;
    this.updateAxisLine();
    $('info').style.display = 'none';
    this.recolor();
    this.updatePrimitives();
    this.borderLines.update(cut);
    for (const overlay of this.overlays) overlay.update(cut);
    const K = cut.size;
    $('clusters-slider').value = String(this.sliderOf(K));
    $('clusters-input').value = String(K);
    const largest = this.tree.largestRms(cut);
    const shown = this.tolerance ?? largest;
    const [a, b] = this.toleranceRange;
    $('tolerance-slider').value = String(shown > 0 ? Math.round(((Math.log(shown) - a) / (b - a)) * 1000) : 0);
    $('tolerance-value').textContent = `${format(shown)} (${format((100 * shown) / this.header.bboxDiagonal)}%)`;
    this.plot.setCurrent(K);
    if (this.relations) this.listRelations();
    const ms = performance.now() - start;
    this.stepTimes.push(ms);
    this.deferRender = false;
    this.render();
    $('status').textContent = `${K.toLocaleString('en')} clusters, largest RMS ${format(largest)}; step ${ms.toFixed(1)} ms`;
  }

  // The colour of a cluster represented by a leaf, as a little-endian RGBA word: computed once
  // per leaf, so that a step costs no allocation and no colour arithmetic per cluster.
  leafColor(leaf) {
    if (!this.leafColors) this.leafColors = new Uint32Array(this.tree.faceCount);
    let word = this.leafColors[leaf];
    if (word === 0) {
      const [r, g, b] = clusterColor(leaf);
      word = this.leafColors[leaf] = (r | (g << 8) | (b << 16) | 0xff000000) >>> 0;
    }
    return word;
  }

  // Colour of each cluster of the current cut: RGBA words (a reused buffer, K long).
  clusterColors() {
    const cut = this.cut, tree = this.tree, K = cut.size, nodes = cut.nodes;
    if (!this.clusterWords || this.clusterWords.length < K) this.clusterWords = new Uint32Array(Math.max(K, 1024));
    const words = this.clusterWords.subarray(0, K);
    const pack = ([r, g, b]) => (r | (g << 8) | (b << 16) | 0xff000000) >>> 0;
    if (testMode) for (let c = 0; c < K; ++c) words[c] = ((c + 1) & 0xffffff | 0xff000000) >>> 0;
    else if (this.colorMode === 'type') {
      const typeWords = TYPE_COLORS.map(pack), grey = pack([128, 128, 128]);
      for (let c = 0; c < K; ++c) words[c] = typeWords[tree.type(nodes[c])] ?? grey;
    } else {
      const representative = tree.representative;
      for (let c = 0; c < K; ++c) words[c] = this.leafColor(representative[nodes[c]]);
    }
    if (this.emphasized >= 0) {
      // The relation's clusters keep their colours; the others fade (to the background in test
      // mode, so that a test sees only the members' codes).
      const member = this.emphasizedClusters();
      const faded = testMode ? 0xff000000 : pack([96, 100, 110]);
      for (let c = 0; c < K; ++c) if (!member[c]) words[c] = faded;
    }
    if (this.selected >= 0 && this.selected < K && !testMode) {
      const w = words[this.selected];
      words[this.selected] = pack([w & 255, (w >> 8) & 255, (w >> 16) & 255].map((x) => Math.round(x + (255 - x) * 0.55)));
    }
    return words;
  }

  /** RGB of cluster c of the current colours. */
  clusterRgb(c) {
    const w = this.currentColors[c];
    return [w & 255, (w >> 8) & 255, (w >> 16) & 255];
  }

  recolor() {
    const words = this.clusterColors();
    this.currentColors = words;
    const nodes = this.cut.nodes, out = this.cornerColors, slotStart = this.slotStart;
    const { leafStart, faces } = this.tree;
    // filled[node]: the colour word a node's range was filled with, for the clusters of the
    // previous fill (else 0): a cluster kept with its colour is not written again.
    if (!this.filled) this.filled = new Uint32Array(this.tree.nodeCount);
    const filled = this.filled;
    // Only the slots whose colour changes are uploaded: [first, last).
    let first = Infinity, last = -1;
    for (let c = 0; c < nodes.length; ++c) {
      const node = nodes[c], word = words[c];
      if (filled[node] === word) continue;
      const from = slotStart[leafStart[node]], to = slotStart[leafStart[node] + faces[node]];
      out.fill(word, 3 * from, 3 * to);
      if (from < first) first = from;
      if (to > last) last = to;
    }
    for (const node of this.filledNodes ?? []) filled[node] = 0;
    for (let c = 0; c < nodes.length; ++c) filled[nodes[c]] = words[c];
    this.filledNodes = nodes;
    if (last > first) {
      this.colorAttribute.clearUpdateRanges();
      this.colorAttribute.addUpdateRange(12 * first, 12 * (last - first));
      this.colorAttribute.needsUpdate = true;
    }
    this.updateLegend();
    this.render();
  }

  updateLegend() {
    const cut = this.cut, tree = this.tree, legend = $('legend');
    const rows = [];
    const swatch = (rgb) => `<span class="swatch" style="background:rgb(${rgb.join(',')})"></span>`;
    if (this.colorMode === 'type') {
      const count = new Array(TYPE_NAMES.length).fill(0), area = new Array(TYPE_NAMES.length).fill(0);
      for (const node of cut.nodes) {
        ++count[tree.type(node)];
        area[tree.type(node)] += tree.area[node];
      }
      const total = area.reduce((x, y) => x + y, 0) || 1;
      rows.push('<tr><td></td><td>type</td><td>clusters</td><td>area</td></tr>');
      TYPE_NAMES.forEach((name, t) => {
        if (count[t]) rows.push(`<tr><td>${swatch(TYPE_COLORS[t])}</td><td>${name}</td><td>${count[t]}</td><td>${(100 * area[t] / total).toFixed(1)}%</td></tr>`);
      });
    } else {
      const largest = tree.largestClusters(cut, 12);
      rows.push('<tr><td></td><td>id</td><td>type</td><td>faces</td></tr>');
      largest.forEach((c, rank) => {
        const node = cut.nodes[c];
        rows.push(`<tr><td>${swatch(this.clusterRgb(c))}</td><td>${rank}</td><td>${TYPE_NAMES[tree.type(node)]}</td><td>${tree.faces[node]}</td></tr>`);
      });
      if (cut.size > largest.length) rows.push(`<tr><td></td><td colspan="3">... ${cut.size - largest.length} more</td></tr>`);
    }
    legend.innerHTML = `<table>${rows.join('')}</table>`;
  }

  // Triangles of each cluster of the current cut (counting sort): {offsets, triangles}, made once
  // per cut (a click, and every cluster of a level in turn, ask again).
  trianglesByCluster() {
    if (this.triangleIndex?.cut === this.cut) return this.triangleIndex;
    const faceCluster = this.cut.faceCluster, faceOfTriangle = this.data.faceOfTriangle;
    const T = this.data.triangles.length / 3, K = this.cut.size;
    const offsets = new Uint32Array(K + 1);
    const clusterOf = (t) => faceCluster[faceOfTriangle ? faceOfTriangle[t] : t];
    for (let t = 0; t < T; ++t) ++offsets[clusterOf(t) + 1];
    for (let c = 0; c < K; ++c) offsets[c + 1] += offsets[c];
    const fill = offsets.slice(0, K), triangles = new Uint32Array(T);
    for (let t = 0; t < T; ++t) triangles[fill[clusterOf(t)]++] = t;
    this.triangleIndex = { cut: this.cut, offsets, triangles };
    return this.triangleIndex;
  }

  updatePrimitives() {
    if (this.primitiveMesh) {
      this.scene.remove(this.primitiveMesh);
      this.primitiveMesh.geometry.dispose();
      this.primitiveMesh = null;
    }
    // The clusters whose primitive is drawn (primseg's reported fit: Tree.primitive).
    this.drawnPrimitives = [];
    if (!$('show-primitives').checked) return this.render();
    const cut = this.cut;
    if (cut.size > MAX_DRAWN_PRIMITIVES) {
      $('status').textContent = `primitives are drawn up to ${MAX_DRAWN_PRIMITIVES} clusters`;
      return this.render();
    }
    const { offsets, triangles } = this.trianglesByCluster();
    const positions = this.data.positions, meshTriangles = this.data.triangles;
    const vertices = [], colors = [], indices = [];
    // An emphasised relation: its members' surfaces only.
    const shown = this.emphasized >= 0 ? this.emphasizedClusters() : null;
    for (let c = 0; c < cut.size; ++c) {
      if (shown && !shown[c]) continue;
      const primitive = this.primitiveOf(c);
      if (!primitive) continue;
      const count = offsets[c + 1] - offsets[c];
      const stride = Math.max(1, Math.floor((3 * count) / MAX_SHAPE_POINTS));
      const points = [];
      for (let k = 0; k < 3 * count; k += stride) {
        const t = triangles[offsets[c] + Math.floor(k / 3)];
        const v = 3 * meshTriangles[3 * t + (k % 3)];
        points.push([positions[v], positions[v + 1], positions[v + 2]]);
      }
      let patch = null;
      if (primitive.type === 0) {
        patch = new Float32Array(9 * count);
        for (let k = 0; k < 3 * count; ++k) {
          const v = 3 * meshTriangles[3 * triangles[offsets[c] + Math.floor(k / 3)] + (k % 3)];
          patch.set(positions.subarray(v, v + 3), 3 * k);
        }
      }
      const surface = primitiveSurface(primitive, points, patch);
      if (!surface) continue;
      this.drawnPrimitives.push(c);
      const base = vertices.length / 3;
      const rgb = this.clusterRgb(c).map((x) => Math.min(255, x + 60) / 255);
      for (let i = 0; i < surface.vertices.length; i += 3) {
        vertices.push(surface.vertices[i], surface.vertices[i + 1], surface.vertices[i + 2]);
        colors.push(...rgb);
      }
      for (const i of surface.indices) indices.push(base + i);
    }
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.Float32BufferAttribute(vertices, 3));
    geometry.setAttribute('color', new THREE.Float32BufferAttribute(colors, 3));
    geometry.setIndex(indices);
    const material = new THREE.MeshBasicMaterial({ vertexColors: true, transparent: true, opacity: 0.45,
      side: THREE.DoubleSide, depthWrite: false });
    this.primitiveMesh = new THREE.Mesh(geometry, material);
    this.primitiveMesh.renderOrder = 1;
    this.scene.add(this.primitiveMesh);
    this.render();
  }

  /**
   * The fit primseg reports for cluster c of the current cut: made exact by the level's
   * relations when the page has them (cut --regularize), else the cluster's own. Or null.
   */
  primitiveOf(c) {
    return this.exactFit(c)?.primitive ?? this.tree.primitive(this.cut.nodes[c]);
  }

  /** Cluster c's fit and errors as the level's relations made them, or null. */
  exactFit(c) {
    return this.levelRelations ? this.relations.fit(this.cut.size, this.cut.nodes[c]) : null;
  }

  /**
   * The relations of a cut, each with its members' indices in the cut (members; others: the
   * other direction of an orthogonal one), or null when the page has none for it: a level
   * beyond --regularize-clusters, or a cut by tolerance that no number of clusters gives.
   */
  relationsOf(cut) {
    const list = this.relations?.at(cut.size);
    if (!list || !this.tree.isCountCut(cut)) return null;
    const index = new Map();
    cut.nodes.forEach((node, c) => index.set(node, c));
    return list.map((r) => ({ ...r, members: r.nodes.map((n) => index.get(n)),
      others: r.otherNodes.map((n) => index.get(n)) }));
  }

  /**
   * The current level's relations with cluster ids as primseg numbers them, as `primseg cut
   * --regularize --json` lists them: [{kind, clusters, orthogonal_to?, deviation}], or null.
   */
  currentRelations() {
    if (!this.levelRelations) return null;
    const ids = this.tree.clusterIds(this.cut);
    const sorted = (list) => list.map((c) => ids[c]).sort((a, b) => a - b);
    return this.levelRelations.map(({ kind, members, others, deviation }) =>
      (kind === 'orthogonal' ? { kind, clusters: sorted(members), orthogonal_to: sorted(others), deviation }
        : { kind, clusters: sorted(members), deviation }));
  }

  /** A relation as the CLI's summary writes it: "parallel: 2 7 24", "orthogonal: 0 | 8 9". */
  relationText(relation) {
    return `${relation.kind.replace('_', ' ')}: ${relation.clusters.join(' ')}` +
      (relation.orthogonal_to ? ` | ${relation.orthogonal_to.join(' ')}` : '');
  }

  /** Lists the current level's relations; a row under the pointer, or clicked, emphasises them. */
  listRelations() {
    const box = $('relations');
    box.textContent = '';
    const relations = this.currentRelations();
    if (!relations) {
      const K = this.cut.size;
      $('relations-summary').textContent = K > this.relations.last
        ? `none listed beyond ${this.relations.last.toLocaleString('en')} clusters (view --regularize-clusters)`
        : 'listed for the levels by number of clusters';
      return;
    }
    $('relations-summary').textContent = relations.length ? '' : 'none at this level';
    relations.forEach((relation, i) => {
      const row = document.createElement('div');
      row.className = 'relation';
      row.dataset.index = String(i);
      let text = this.relationText(relation);
      if (relation.kind === 'equal_radius') text += `, r = ${format(this.primitiveOf(this.levelRelations[i].members[0]).radius)}`;
      if (relation.kind === 'concentric') {
        text += `, r = ${this.levelRelations[i].members.map((c) => format(this.primitiveOf(c).radius)).join(' and ')}`;
      }
      if (relation.kind === 'tangent') {
        const radii = this.levelRelations[i].members.map((c) => this.primitiveOf(c))
          .filter((p) => TYPE_NAMES[p.type] === 'cylinder').map((p) => format(p.radius));
        if (radii.length) text += `, r = ${radii.join(' and ')}`;
      }
      const angular = relation.kind === 'parallel' || relation.kind === 'orthogonal';
      text += `, off by ${format(relation.deviation)}${angular ? '°' : ''}`;
      row.textContent = text;
      row.title = `${RELATION_MEANINGS[relation.kind] ?? relation.kind}; the own fits were off by ` +
        `${format(relation.deviation)}${angular ? ' degrees' : ' (input units)'} before`;
      row.addEventListener('pointerenter', () => this.emphasize(i));
      row.addEventListener('pointerleave', () => this.emphasize(this.pinned));
      row.addEventListener('click', () => {
        this.pinned = this.pinned === i ? -1 : i;
        this.emphasize(this.pinned);
      });
      box.appendChild(row);
    });
  }

  /** Makes relation i of the current level stand out (-1: none): its clusters alone in colour
   *  and with their primitives drawn. */
  emphasize(i) {
    if (!this.levelRelations || i >= this.levelRelations.length) i = -1;
    if (i === this.emphasized) return;
    this.emphasized = i;
    for (const row of $('relations').children)
      row.classList.toggle('emphasized', Number(row.dataset.index) === i || Number(row.dataset.index) === this.pinned);
    this.deferRender = true;
    this.recolor();
    this.updatePrimitives();
    this.updateAxisLine();
    this.deferRender = false;
    this.render();
  }

  /**
   * The shared axis of an emphasised coaxial relation (its cylinders' axis, its spheres' centres),
   * drawn through the mesh over the length of its clusters (plus a tenth at each end): this.axisLine, its ends [2][3] relative to
   * header.center, or null.
   */
  updateAxisLine() {
    if (this.axisObject) {
      this.scene.remove(this.axisObject);
      this.axisObject.geometry.dispose();
      this.axisObject = null;
    }
    this.axisLine = null;
    const relation = this.emphasized >= 0 ? this.levelRelations[this.emphasized] : null;
    if (relation?.kind !== 'coaxial') return;
    // Its line is its cylinders' (its spheres are centred on it), or without a cylinder the one
    // through its spheres' centres (the two farthest apart; none when they are one point).
    const cylinder = relation.members.find((c) => TYPE_NAMES[this.primitiveOf(c).type] === 'cylinder');
    let point, axis;
    if (cylinder !== undefined) {
      ({ point, axis } = this.primitiveOf(cylinder));
    } else {
      const centres = relation.members.map((c) => this.primitiveOf(c).point);
      let far = [0, 0], longest = 0;
      centres.forEach((a, i) => centres.forEach((b, j) => {
        const d = Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
        if (d > longest) [longest, far] = [d, [i, j]];
      }));
      if (!(longest > 0)) return;
      point = centres[far[0]];
      axis = centres[far[1]].map((x, a) => (x - point[a]) / longest);
    }
    const { offsets, triangles } = this.trianglesByCluster();
    const positions = this.data.positions, meshTriangles = this.data.triangles;
    let low = Infinity, high = -Infinity;
    for (const c of relation.members)
      for (let i = offsets[c]; i < offsets[c + 1]; ++i)
        for (let k = 0; k < 3; ++k) {
          const v = 3 * meshTriangles[3 * triangles[i] + k];
          const t = (positions[v] - point[0]) * axis[0] + (positions[v + 1] - point[1]) * axis[1] +
            (positions[v + 2] - point[2]) * axis[2];
          low = Math.min(low, t);
          high = Math.max(high, t);
        }
    const margin = (high - low) / 10;
    this.axisLine = [low - margin, high + margin].map((t) => point.map((x, a) => x + t * axis[a]));
    if (testMode) return;  // the pixels stay cluster codes
    const geometry = new THREE.BufferGeometry().setFromPoints(this.axisLine.map((p) => new THREE.Vector3(...p)));
    this.axisObject = new THREE.Line(geometry, new THREE.LineBasicMaterial({ color: 0xffd36b, depthTest: false, transparent: true }));
    this.axisObject.renderOrder = 5;
    this.scene.add(this.axisObject);
  }

  /** 1 for each cluster of the current cut in the emphasised relation (Uint8Array, K). */
  emphasizedClusters() {
    const member = new Uint8Array(this.cut.size);
    const { members, others } = this.levelRelations[this.emphasized];
    for (const c of members) member[c] = 1;
    for (const c of others) member[c] = 1;
    return member;
  }

  /** The cluster under a point of the window (client coordinates), or -1. */
  clusterAt(x, y) {
    const rect = this.renderer.domElement.getBoundingClientRect();
    const pointer = new THREE.Vector2(((x - rect.left) / rect.width) * 2 - 1, -((y - rect.top) / rect.height) * 2 + 1);
    const raycaster = new THREE.Raycaster();
    raycaster.setFromCamera(pointer, this.camera);
    const hit = raycaster.intersectObject(this.mesh, false)[0];
    if (!hit) return { cluster: -1 };
    const triangle = this.drawOrder[hit.faceIndex];
    const face = this.data.faceOfTriangle ? this.data.faceOfTriangle[triangle] : triangle;
    return { cluster: this.cut.faceCluster[face], face };
  }

  /** Selects the cluster under a window point and shows its details; returns them. */
  pick(x, y) {
    const { cluster, face } = this.clusterAt(x, y);
    this.selected = cluster;
    this.recolor();
    if (cluster < 0) {
      $('info').style.display = 'none';
      this.info = null;
      return null;
    }
    this.info = this.describe(cluster, face);
    this.showInfo(this.info);
    return this.info;
  }

  /** What a user wants to know about a cluster of the current cut. */
  describe(c, face) {
    const tree = this.tree, node = this.cut.nodes[c], header = this.header;
    const { offsets, triangles } = this.trianglesByCluster();
    const clusterTriangles = triangles.subarray(offsets[c], offsets[c + 1]);
    const exact = this.exactFit(c);
    const primitive = exact?.primitive ?? tree.primitive(node) ??
      (tree.isLeaf(node) ? facePlane(this.data.positions, this.data.triangles, clusterTriangles) : null);
    const clusterIds = tree.clusterIds(this.cut);
    const info = {
      id: clusterIds[c], clusters: this.cut.size, node, face,
      type: TYPE_NAMES[tree.type(node)], faces: tree.faces[node], area: tree.area[node],
      rmsEstimate: tree.rms(node),
    };
    if (primitive) {
      // primseg's own figures where the page carries them; else (a single face of a fine level)
      // measured here, on the page's float32 positions.
      const { rms, max } = exact?.errors ?? tree.errors(node) ??
        clusterErrors(primitive, this.data.positions, this.data.triangles, clusterTriangles, this.cornerWeight());
      info.rms = rms;
      info.max = max;
      const center = header.center;
      const point = primitive.point.map((x, a) => x + center[a]);
      const p = { plane: { normal: primitive.axis, point }, cylinder: { axis: primitive.axis, point, radius: primitive.radius },
        sphere: { center: point, radius: primitive.radius }, cone: { apex: point, axis: primitive.axis, half_angle: primitive.halfAngle },
        torus: { center: point, axis: primitive.axis, major_radius: primitive.radius, minor_radius: primitive.minorRadius } };
      info.params = p[TYPE_NAMES[primitive.type]];
    }
    if (this.levelRelations) {
      info.relations = this.currentRelations().filter((r, i) =>
        this.levelRelations[i].members.includes(c) || this.levelRelations[i].others.includes(c));
    }
    // Its borders: the neighbouring clusters (ids as primseg numbers them, null for the open
    // boundary), with the angle between the fitted surfaces across each.
    info.borders = this.borderLines.clusterBorders(this.cut, c, clusterTriangles, (k) => this.primitiveOf(k))
      .map((b) => ({ ...b, cluster: b.cluster < 0 ? null : clusterIds[b.cluster],
        type: b.cluster < 0 ? null : TYPE_NAMES[tree.type(this.cut.nodes[b.cluster])] }));
    return info;
  }

  // Corner weights as primseg's: area / 3, or 1 / (triangles at the vertex) for uniform weights.
  cornerWeight() {
    if (this.header.weights !== 'uniform') return (t) => this.tree.triangleArea[t] / 3;
    if (!this.valence) {
      this.valence = new Uint32Array(this.header.vertices);
      for (const v of this.data.triangles) ++this.valence[v];
    }
    return (t, v) => 1 / this.valence[v];
  }

  showInfo(info) {
    const rows = [['type', info.type], ['faces', info.faces.toLocaleString('en')], ['area', format(info.area)]];
    if (info.params) for (const [key, value] of Object.entries(info.params)) rows.push([key, Array.isArray(value) ? formatVector(value) : format(value)]);
    else rows.push(['parameters', 'not in the page at this level (too fine)']);
    if (info.rms !== undefined) rows.push(['RMS', format(info.rms)], ['max error', format(info.max)]);
    if (info.relations?.length) rows.push(['relations', info.relations.map((r) => this.relationText(r)).join('<br>')]);
    rows.push(['RMS estimate', format(info.rmsEstimate)]);
    // The longest borders: whom it meets, and how (0 degrees tangent, 90 a square edge).
    const shown = info.borders.slice(0, 6).map((b) => (b.cluster === null ? 'open boundary'
      : `${b.cluster} (${b.type})${b.angle === null ? '' : ` at ${b.angle.toFixed(1)}&deg;`}`) +
      `, ${b.length.toPrecision(3)} long`);
    if (info.borders.length > shown.length) shown.push(`... ${info.borders.length - shown.length} more`);
    if (shown.length) rows.push(['meets', shown.join('<br>')]);
    const panel = $('info');
    panel.innerHTML = `<h2>cluster ${info.id} of ${info.clusters}</h2><table>${rows.map(([k, v]) => `<tr><td>${k}</td><td>${v}</td></tr>`).join('')}</table>`;
    panel.style.display = 'block';
  }

  /** The labels of every input face, numbered as primseg numbers them (by decreasing area). */
  labels() {
    const ids = this.tree.clusterIds(this.cut);
    return Array.from(this.cut.faceCluster, (c) => ids[c]);
  }

  /** The canvas's pixels after a render, RGBA rows bottom-up, as base64. */
  readPixels() {
    this.render();
    const gl = this.renderer.getContext();
    const w = gl.drawingBufferWidth, h = gl.drawingBufferHeight;
    const pixels = new Uint8Array(w * h * 4);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
    let binary = '';
    for (let i = 0; i < pixels.length; i += 0x8000) binary += String.fromCharCode.apply(null, pixels.subarray(i, i + 0x8000));
    return { width: w, height: h, rgba: btoa(binary) };
  }
}

function showError(error) {
  const box = $('error');
  box.textContent = 'primseg viewer: ' + (error && error.message ? error.message : String(error));
  box.style.display = 'block';
  console.error(error);
}

const ready = (async () => {
  const start = performance.now();
  const data = await readPageData(document);
  const decoded = performance.now();
  const viewer = new Viewer(data);
  viewer.render();
  viewer.loadMs = performance.now() - start;
  viewer.loadTimes = { decodeMs: decoded - start, viewerMs: performance.now() - decoded };
  return viewer;
})();
ready.catch(showError);

// The skeleton's interface (pages written with --skeleton): poses as primseg deform's POSE.json
// reads them, {"rotations": [{"joint", "axis", "degrees"}]}, and the posed vertices.
async function skeletonOf() {
  const viewer = await ready;
  if (!viewer.skeleton) throw new Error('this page has no skeleton: write it with primseg view --skeleton');
  return viewer.skeleton;
}

window.primseg = {
  ready,
  testMode,
  /** Poses the mesh (joints left out go back to rest); throws for a pose primseg refuses. */
  setPose: async (pose) => (await skeletonOf()).setPose(pose),
  /** The current pose, as a POSE.json object. */
  pose: async () => (await skeletonOf()).pose(),
  /** Posed vertex positions, input units: an Array of V*3 numbers. */
  deformedPositions: async () => Array.from((await skeletonOf()).positions()),
};
