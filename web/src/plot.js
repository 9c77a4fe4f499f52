// The error-versus-number-of-clusters curve: the whole mesh's area-weighted RMS estimate at each
// level K (logarithmic K axis), the current level marked, automatic levels ticked; a click
// picks a level.

export class ErrorPlot {
  /**
   * @param canvas the <canvas> to draw on
   * @param curve Float64Array, curve[K] for K in 0..F
   * @param onPick called with the K under a click
   */
  constructor(canvas, curve, minClusters, onPick) {
    this.canvas = canvas;
    this.curve = curve;
    this.faces = curve.length - 1;
    this.minClusters = minClusters;
    this.levels = [];
    this.current = 1;
    this.margin = { left: 44, right: 8, top: 8, bottom: 22 };
    const pick = (event) => {
      const rect = canvas.getBoundingClientRect();
      const x = event.clientX - rect.left;
      onPick(this.levelAt(x) ?? this.clustersAt(x));
    };
    canvas.addEventListener('click', pick);
    canvas.addEventListener('pointermove', (event) => {
      if (event.buttons === 1) pick(event);
    });
  }

  width() {
    return this.canvas.clientWidth - this.margin.left - this.margin.right;
  }

  x(K) {
    const span = Math.log(Math.max(2, this.faces));
    return this.margin.left + (Math.log(Math.max(1, K)) / span) * this.width();
  }

  clustersAt(x) {
    const fraction = Math.min(1, Math.max(0, (x - this.margin.left) / this.width()));
    return Math.max(1, Math.min(this.faces, Math.round(Math.exp(fraction * Math.log(Math.max(2, this.faces))))));
  }

  /** The automatic level whose mark is within a few pixels of x (nearest), or null. */
  levelAt(x, pixels = 5) {
    let best = null, bestDistance = pixels;
    for (const { clusters } of this.levels) {
      const distance = Math.abs(this.x(clusters) - x);
      if (distance <= bestDistance) {
        best = clusters;
        bestDistance = distance;
      }
    }
    return best;
  }

  /** Where each automatic level is marked: [{clusters, x, y}] in CSS pixels of the canvas. */
  levelMarks() {
    const h = this.canvas.clientHeight;
    return this.levels.map(({ clusters }) => ({ clusters, x: this.x(clusters), y: h - this.margin.bottom + 3 }));
  }

  /** Automatic levels to mark on the K axis: [{clusters, score}], the chosen one's K. */
  setLevels(levels, chosen) {
    this.levels = levels;
    this.chosen = chosen;
    this.draw();
  }

  setCurrent(K) {
    this.current = K;
    this.draw();
  }

  draw() {
    const canvas = this.canvas, ratio = window.devicePixelRatio || 1;
    const w = canvas.clientWidth, h = canvas.clientHeight;
    if (canvas.width !== Math.round(w * ratio)) {
      canvas.width = Math.round(w * ratio);
      canvas.height = Math.round(h * ratio);
    }
    const g = canvas.getContext('2d');
    g.setTransform(ratio, 0, 0, ratio, 0, 0);
    g.clearRect(0, 0, w, h);
    const m = this.margin, plotH = h - m.top - m.bottom;
    const top = this.curve[Math.max(1, this.minClusters)] || 1;
    const y = (value) => m.top + plotH * (1 - Math.min(1, value / top));
    g.strokeStyle = '#555b68';
    g.strokeRect(m.left, m.top, this.width(), plotH);
    g.fillStyle = '#b8bcc6';
    g.font = '10px system-ui, sans-serif';
    g.textAlign = 'center';
    for (let K = 1; K <= this.faces; K *= 10) g.fillText(String(K), this.x(K), h - 8);
    g.textAlign = 'right';
    g.fillText('clusters (log)', m.left + this.width() - 4, m.top + 12);
    g.textAlign = 'center';
    g.textAlign = 'right';
    g.fillText(top.toPrecision(2), m.left - 3, m.top + 8);
    g.fillText('0', m.left - 3, m.top + plotH);
    g.save();
    g.translate(10, m.top + plotH / 2);
    g.rotate(-Math.PI / 2);
    g.textAlign = 'center';
    g.fillText('RMS', 0, 0);
    g.restore();

    g.strokeStyle = '#9fd3ff';
    g.lineWidth = 1.5;
    g.beginPath();
    const samples = Math.max(2, Math.round(this.width()));
    for (let i = 0; i <= samples; ++i) {
      const K = this.clustersAt(m.left + (i / samples) * this.width());
      const px = m.left + (i / samples) * this.width(), py = y(this.curve[K]);
      if (i === 0) g.moveTo(px, py);
      else g.lineTo(px, py);
    }
    g.stroke();

    for (const { clusters: K } of this.levels) {
      const px = this.x(K);
      // A dashed line up to the curve, a triangle under the axis (filled for the chosen level).
      g.strokeStyle = 'rgba(255, 211, 107, 0.55)';
      g.setLineDash([2, 3]);
      g.beginPath();
      g.moveTo(px, m.top + plotH);
      g.lineTo(px, y(this.curve[K]));
      g.stroke();
      g.setLineDash([]);
      g.fillStyle = K === this.chosen ? '#ffd36b' : 'rgba(255, 211, 107, 0.5)';
      g.beginPath();
      g.moveTo(px, m.top + plotH);
      g.lineTo(px - 4, m.top + plotH + 6);
      g.lineTo(px + 4, m.top + plotH + 6);
      g.fill();
    }

    const cx = this.x(this.current);
    g.strokeStyle = '#ff7b7b';
    g.lineWidth = 1;
    g.beginPath();
    g.moveTo(cx, m.top);
    g.lineTo(cx, m.top + plotH);
    g.stroke();
    g.fillStyle = '#ff7b7b';
    g.beginPath();
    g.arc(cx, y(this.curve[this.current]), 3.5, 0, 2 * Math.PI);
    g.fill();
  }
}
