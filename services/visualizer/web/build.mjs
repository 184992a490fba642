// Bundles the page with esbuild: src/app.js (three.js, uPlot and fahr's
// code) into one minified app.js, and copies index.html and the CSS beside it.
//   node build.mjs OUT_DIR
import { build } from "esbuild";
import { copyFileSync, mkdirSync } from "node:fs";
import { join } from "node:path";

const out = process.argv[2] ?? "dist";
mkdirSync(out, { recursive: true });
await build({
  entryPoints: ["src/app.js"],
  bundle: true,
  minify: true,
  format: "esm",
  target: "es2020",
  outfile: join(out, "app.js"),
  loader: { ".css": "css" },
  logLevel: "warning",
});
copyFileSync("src/index.html", join(out, "index.html"));
