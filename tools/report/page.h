// The page around fahr_report's data: styles and the plotting script
// (inline SVG, no library, works offline). The data goes between kHead and
// kTail as one JSON object assigned to `fahrReport`.
#pragma once

namespace fahr::report {

inline constexpr const char* kHead = R"html(<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<title>fahr run report</title>
<style>
body { font-family: sans-serif; margin: 24px; color: #222; max-width: 1100px; }
h1 { font-size: 22px; } h2 { font-size: 16px; margin-top: 28px; }
.plot { border: 1px solid #ccc; margin: 6px 0; }
.note { color: #666; font-size: 13px; }
table { border-collapse: collapse; font-size: 13px; } td, th { border: 1px solid #ccc; padding: 2px 8px; }
.legend span { margin-right: 14px; font-size: 13px; }
</style></head><body>
<h1>fahr run report</h1>
<div id="meta"></div>
<div id="plots"></div>
<div id="fahr-check" data-errors="0" data-plots="0" data-min-points="0"></div>
<script>
var fahrErrors = 0;
function fahrError() { fahrErrors++; var c = document.getElementById('fahr-check'); if (c) c.dataset.errors = fahrErrors; }
window.onerror = fahrError;
(function () { var e = console.error; console.error = function () { fahrError(); e.apply(console, arguments); }; })();
var fahrReport = )html";

inline constexpr const char* kTail = R"html(;
(function () {
  var colours = ['#1f77b4', '#d62728', '#2ca02c', '#9467bd', '#ff7f0e', '#8c564b', '#17becf'];
  var NS = 'http://www.w3.org/2000/svg';
  function el(name, attrs, parent) {
    var e = document.createElementNS(NS, name);
    for (var k in attrs) e.setAttribute(k, attrs[k]);
    if (parent) parent.appendChild(e);
    return e;
  }
  function niceTicks(lo, hi, n) {
    var span = hi - lo || 1, step = Math.pow(10, Math.floor(Math.log10(span / n)));
    [1, 2, 5, 10].some(function (m) { if (span / (step * m) <= n) { step *= m; return true; } return false; });
    var out = [];
    for (var v = Math.ceil(lo / step) * step; v <= hi + 1e-12; v += step) out.push(v);
    return out;
  }
  var minPoints = Infinity, plots = 0;
  function plot(p) {
    var box = document.createElement('div');
    var h = document.createElement('h2'); h.textContent = p.title; box.appendChild(h);
    if (p.note) { var n = document.createElement('div'); n.className = 'note'; n.textContent = p.note; box.appendChild(n); }
    var W = 1000, H = 300, L = 60, R = 10, T = 10, B = 40;
    var svg = el('svg', { width: W, height: H, class: 'plot', viewBox: '0 0 ' + W + ' ' + H }, box);
    var xs = [], ys = [], points = 0;
    p.series.forEach(function (s) { for (var i = 0; i < s.x.length; i++) { xs.push(s.x[i]); ys.push(s.y[i]); } points += s.x.length; });
    (p.bands || []).forEach(function (b) { xs.push(b[0], b[1]); });
    if (xs.length === 0) { var e = document.createElement('div'); e.className = 'note'; e.textContent = 'no data'; box.appendChild(e); document.getElementById('plots').appendChild(box); return; }
    var x0 = Math.min.apply(null, xs), x1 = Math.max.apply(null, xs);
    var y0 = p.y0 !== undefined ? p.y0 : Math.min.apply(null, ys), y1 = Math.max.apply(null, ys);
    if (y1 === y0) y1 = y0 + 1;
    if (x1 === x0) x1 = x0 + 1;
    function X(v) { return L + (v - x0) / (x1 - x0) * (W - L - R); }
    function Y(v) { return H - B - (v - y0) / (y1 - y0) * (H - T - B); }
    (p.bands || []).forEach(function (b) {
      el('rect', { x: X(b[0]), y: T, width: Math.max(1, X(b[1]) - X(b[0])), height: H - T - B, fill: '#f4c7c3' }, svg);
    });
    niceTicks(x0, x1, 10).forEach(function (v) {
      el('line', { x1: X(v), x2: X(v), y1: T, y2: H - B, stroke: '#eee' }, svg);
      el('text', { x: X(v), y: H - B + 16, 'font-size': 11, 'text-anchor': 'middle' }, svg).textContent = +v.toPrecision(6);
    });
    niceTicks(y0, y1, 6).forEach(function (v) {
      el('line', { x1: L, x2: W - R, y1: Y(v), y2: Y(v), stroke: '#eee' }, svg);
      el('text', { x: L - 6, y: Y(v) + 4, 'font-size': 11, 'text-anchor': 'end' }, svg).textContent = +v.toPrecision(6);
    });
    el('text', { x: (L + W - R) / 2, y: H - 6, 'font-size': 12, 'text-anchor': 'middle' }, svg).textContent = p.xlabel;
    el('text', { x: 14, y: (T + H - B) / 2, 'font-size': 12, 'text-anchor': 'middle', transform: 'rotate(-90 14 ' + (T + H - B) / 2 + ')' }, svg).textContent = p.ylabel;
    var legend = document.createElement('div'); legend.className = 'legend';
    p.series.forEach(function (s, k) {
      var d = '';
      for (var i = 0; i < s.x.length; i++) d += (i ? 'L' : 'M') + X(s.x[i]).toFixed(1) + ' ' + Y(s.y[i]).toFixed(1);
      el('path', { d: d, fill: 'none', stroke: colours[k % colours.length], 'stroke-width': 1.2 }, svg);
      var sp = document.createElement('span'); sp.style.color = colours[k % colours.length];
      sp.textContent = '\u25A0 ' + s.name + ' (' + s.x.length + ' points)'; legend.appendChild(sp);
    });
    if (p.bands && p.bands.length) { var sp = document.createElement('span'); sp.style.color = '#d9776d'; sp.textContent = '\u25A0 ' + p.bandName + ' (' + p.bands.length + ')'; legend.appendChild(sp); }
    box.appendChild(legend);
    document.getElementById('plots').appendChild(box);
    plots++;
    minPoints = Math.min(minPoints, points);
  }
  var meta = document.getElementById('meta');
  var t = document.createElement('table');
  fahrReport.meta.forEach(function (kv) {
    var tr = document.createElement('tr');
    var a = document.createElement('th'); a.textContent = kv[0]; var b = document.createElement('td'); b.textContent = kv[1];
    tr.appendChild(a); tr.appendChild(b); t.appendChild(tr);
  });
  meta.appendChild(t);
  fahrReport.plots.forEach(plot);
  var check = document.getElementById('fahr-check');
  check.dataset.plots = plots;
  check.dataset.minPoints = plots ? minPoints : 0;
})();
</script></body></html>
)html";

}  // namespace fahr::report
