#!/usr/bin/env bash
# Re-create the browser libraries that the book serves itself (book/_vendor/),
# from the npm registry. Building the book does NOT run this: the files it
# makes are committed, so `pip install -r requirements.txt && jupyter-book build .`
# works offline and needs no Node.js. Run it (needs npm) only to change a version,
# then commit the result; SHA256SUMS records what was vendored.
#
# _config.yml serves this folder through html_static_path, so its files land in
# _build/html/_static/: mathjax/ (mathjax_path) and widgets/ (nb_ipywidgets_js).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")"

MATHJAX=3.2.2                  # MathJax 3, what Sphinx 7 targets
HTML_MANAGER=1.0.15            # @jupyter-widgets/html-manager for ipywidgets 8
ORT=1.30.0                     # onnxruntime-web: the live playground runs the models (book/_js/pgae.js)
TOKENIZERS=0.2.0               # @huggingface/tokenizers: free text in the page, tokenized as in Python

tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
# `npm pack` fetches just the published tarballs (no dependencies, no install scripts).
npm pack --silent --pack-destination "$tmp" "mathjax@$MATHJAX" "@jupyter-widgets/html-manager@$HTML_MANAGER" \
    "onnxruntime-web@$ORT" "@huggingface/tokenizers@$TOKENIZERS" >/dev/null
mkdir "$tmp/mathjax" "$tmp/widgets" "$tmp/ort" "$tmp/tokenizers"
tar xzf "$tmp"/mathjax-*.tgz -C "$tmp/mathjax" --strip-components=1
tar xzf "$tmp"/jupyter-widgets-html-manager-*.tgz -C "$tmp/widgets" --strip-components=1
tar xzf "$tmp"/onnxruntime-web-*.tgz -C "$tmp/ort" --strip-components=1
tar xzf "$tmp"/huggingface-tokenizers-*.tgz -C "$tmp/tokenizers" --strip-components=1

rm -rf mathjax widgets ort tokenizers
# MathJax: the *full* TeX bundle has every TeX extension built in, so nothing is
# loaded lazily ("autoload") at reading time; plus the CHTML fonts it asks for,
# found relative to the script (output/chtml/fonts/woff-v2).
mkdir -p mathjax/output/chtml/fonts
cp "$tmp/mathjax/es5/tex-chtml-full.js" "$tmp/mathjax/LICENSE" mathjax/
cp -r "$tmp/mathjax/es5/output/chtml/fonts/woff-v2" mathjax/output/chtml/fonts/
# Widgets: embed.js is the standalone bundle (built-in ipywidgets controls and
# Output, no RequireJS needed); it renders the widget state myst-nb saves in the
# page. Its Font Awesome icons are woff2 files beside it (Chromium and Firefox take
# woff2 and skip the older formats).
mkdir widgets
cp "$tmp/widgets/dist/embed.js" "$tmp/widgets/dist/embed.js.LICENSE.txt" "$tmp"/widgets/dist/*.woff2 widgets/

# onnxruntime-web: the WebAssembly build alone (no WebGL/WebGPU), its loader and the single .wasm it
# loads (SIMD; threads only where the page is cross-origin isolated, else one thread). package.json
# holds its licence (MIT).
mkdir ort
cp "$tmp/ort/dist/ort.wasm.min.js" "$tmp/ort/dist/ort-wasm-simd-threaded.mjs" \
   "$tmp/ort/dist/ort-wasm-simd-threaded.wasm" "$tmp/ort/package.json" ort/

# @huggingface/tokenizers: the minified ES module alone (no dependencies), loaded by pgae.js only when a
# reader types free text; its licence (Apache-2.0) beside it.
mkdir tokenizers
cp "$tmp/tokenizers/dist/tokenizers.min.mjs" "$tmp/tokenizers/LICENSE" "$tmp/tokenizers/package.json" tokenizers/

find mathjax widgets ort tokenizers -type f | LC_ALL=C sort | xargs sha256sum > SHA256SUMS
echo "vendored mathjax@$MATHJAX, @jupyter-widgets/html-manager@$HTML_MANAGER, onnxruntime-web@$ORT," \
     "@huggingface/tokenizers@$TOKENIZERS: $(du -sh --exclude=update.sh . | cut -f1)"
