#!/usr/bin/env bash
# Vendor three.js for the dashboard's 3D view from the npm registry: a pinned version whose
# tarball must match the recorded integrity; the licence is kept next to the files. The
# dashboard serves them itself (no CDN). Re-run after changing VERSION / INTEGRITY.
set -euo pipefail
VERSION=0.170.0
INTEGRITY="sha512-FQK+LEpYc0fBD+J8g6oSEyyNzjp+Q7Ks1C568WWaoMRLW+TkNNWmenWeGgJjV105Gd+p/2ql1ZcjYvNiPZBhuQ=="
DEST="$(cd "$(dirname "$0")/.." && pwd)/src/roverlab/viz/static/vendor/three"
TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT
(cd "$TMP" && npm pack --silent "three@$VERSION" >/dev/null)
TGZ="$TMP/three-$VERSION.tgz"
GOT="sha512-$(openssl dgst -sha512 -binary "$TGZ" | base64 -w0)"
if [ "$GOT" != "$INTEGRITY" ]; then
  echo "error: three@$VERSION tarball integrity $GOT != $INTEGRITY" >&2
  exit 1
fi
tar -xzf "$TGZ" -C "$TMP"
mkdir -p "$DEST/addons/controls" "$DEST/addons/loaders" "$DEST/addons/utils" "$DEST/addons/lines"
cp "$TMP/package/build/three.module.min.js" "$TMP/package/LICENSE" "$DEST/"
cp "$TMP/package/examples/jsm/controls/OrbitControls.js" "$DEST/addons/controls/"
cp "$TMP/package/examples/jsm/loaders/STLLoader.js" "$TMP/package/examples/jsm/loaders/ColladaLoader.js" "$DEST/addons/loaders/"
cp "$TMP/package/examples/jsm/loaders/TGALoader.js" "$DEST/addons/loaders/"
for f in Line2 LineGeometry LineMaterial LineSegments2 LineSegmentsGeometry; do  # Marker line widths
  cp "$TMP/package/examples/jsm/lines/$f.js" "$DEST/addons/lines/"
done
echo "three@$VERSION ($INTEGRITY), from the npm registry by scripts/vendor-three.sh" > "$DEST/VERSION"
echo "vendored three@$VERSION into $DEST"
