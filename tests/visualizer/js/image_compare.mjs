// A rendered frame against a reference image, both PNG (pngjs decodes
// them): per pixel the largest of the three channel differences (0-255);
// the frame matches when few pixels differ by more than a step and the mean
// difference stays small.
//
// Why these numbers: the same chromium build renders a scene bit for bit
// alike through SwiftShader, so a repeated rest frame differs by 0. Another
// chromium or SwiftShader version moves antialiased edges by a fraction of
// a pixel: those pixels differ, but few of them (edges are a small part of
// the frame) and rarely by much. A real change (the camera a millimetre
// off, a colour map off by a tenth, a body missing or moved) changes many
// pixels or changes them a lot. So: at most 0.5 % of the pixels may differ
// by more than 32 (an eighth of full scale), and the mean over all pixels
// of the largest channel difference must stay below 0.6. Measured on the
// held rest frame (tests/visualizer/README.md) of the shipped scene: the
// same state drawn twice 0 and 0; two frames of the hand's first second
// (0.145 s against 0.242 s: the tongue settles on its yielding floor)
// 0.31 % and 0.40; the camera turned 2.9 mm 0.80 % and 1.31; the tongue's
// colours 10 % off 0.32 % and 2.17.
import { PNG } from "pngjs";

export const TOLERANCE = { step: 32, shareAbove: 0.005, meanAbs: 0.6 };

export function decodePng(buffer) {
  return PNG.sync.read(buffer);
}

export function encodePng(image) {
  return PNG.sync.write(image);
}

// { width, height, shareAbove, meanAbs, maxAbs, within } of a against b;
// images of different sizes never match.
export function compareImages(a, b, tolerance = TOLERANCE) {
  if (a.width !== b.width || a.height !== b.height) {
    return { sizeMismatch: `${a.width}x${a.height} against ${b.width}x${b.height}`, within: false };
  }
  const pixels = a.width * a.height;
  let above = 0;
  let sum = 0;
  let maxAbs = 0;
  for (let i = 0; i < a.data.length; i += 4) {
    const d = Math.max(
      Math.abs(a.data[i] - b.data[i]),
      Math.abs(a.data[i + 1] - b.data[i + 1]),
      Math.abs(a.data[i + 2] - b.data[i + 2]),
    );
    if (d > tolerance.step) above++;
    sum += d;
    maxAbs = Math.max(maxAbs, d);
  }
  const shareAbove = above / pixels;
  const meanAbs = sum / pixels;
  return {
    width: a.width,
    height: a.height,
    shareAbove: Number(shareAbove.toFixed(5)),
    meanAbs: Number(meanAbs.toFixed(3)),
    maxAbs,
    within: shareAbove <= tolerance.shareAbove && meanAbs <= tolerance.meanAbs,
  };
}

// A copy of the image with the pixels inside rect (pixels; clipped) that
// differ from the background colour scaled by `factor`: the tongue's colour
// map off by that much, for showing that the comparison catches it.
export function scaledInRect(image, rect, factor, background) {
  const out = new PNG({ width: image.width, height: image.height });
  image.data.copy(out.data);
  const x0 = Math.max(0, Math.floor(rect.x));
  const y0 = Math.max(0, Math.floor(rect.y));
  const x1 = Math.min(image.width, Math.ceil(rect.x + rect.w));
  const y1 = Math.min(image.height, Math.ceil(rect.y + rect.h));
  for (let y = y0; y < y1; y++) {
    for (let x = x0; x < x1; x++) {
      const i = 4 * (y * image.width + x);
      const isBackground =
        out.data[i] === background[0] && out.data[i + 1] === background[1] && out.data[i + 2] === background[2];
      if (isBackground) continue;
      for (let c = 0; c < 3; c++) out.data[i + c] = Math.round(out.data[i + c] * factor);
    }
  }
  return out;
}
