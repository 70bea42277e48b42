#!/usr/bin/env bash
# Regenerates the compressed copies of the Blender exports with other tools' encoders (not run by the
# tests; the outputs are committed): Draco with glTF Transform's CLI (npm @gltf-transform/cli, in a
# scratch folder outside the repository) and meshopt with Debian's gltfpack (apt-get install gltfpack).
#   suzanne_draco.glb, textured_box_draco.glb     gltf-transform draco (14-bit positions by default)
#   dense_monkey_draco.glb                        the same, and the 412 KB original is removed
#   suzanne_meshopt.glb                           gltfpack -c (meshopt, quantized: KHR_mesh_quantization)
#   textured_box_meshopt.glb                      gltfpack -cc -noq (meshopt with filters, float data)
#   textured_box_quantized.glb                    gltfpack (quantized; UVs dequantized by KHR_texture_transform)
#   textured_box_gltf.zip                         gltf-transform copy to .gltf + .bin + PNG, zipped
#   textured_box_normalmap_mikk.glb               its checker as a normal map too, gltf-transform tangents (MikkTSpace)
# usage: tests/data/corpus/compress.sh [SCRATCH_DIR]
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
scratch="${1:-/tmp/gis-gltf-transform}"
mkdir -p "$scratch"
if [[ ! -x "$scratch/node_modules/.bin/gltf-transform" ]]; then
    (cd "$scratch" && npm init -y >/dev/null && npm install --no-audit --no-fund @gltf-transform/cli@4 >/dev/null)
fi
for name in suzanne textured_box; do
    "$scratch/node_modules/.bin/gltf-transform" draco "$here/$name.glb" "$here/${name}_draco.glb"
done
# dense_monkey.glb (412 KB from Blender) is kept only as its Draco copy (56 KB).
if [[ -f "$here/dense_monkey.glb" ]]; then
    "$scratch/node_modules/.bin/gltf-transform" draco "$here/dense_monkey.glb" "$here/dense_monkey_draco.glb"
    rm "$here/dense_monkey.glb"
fi
gltfpack -i "$here/suzanne.glb" -o "$here/suzanne_meshopt.glb" -c
gltfpack -i "$here/textured_box.glb" -o "$here/textured_box_meshopt.glb" -cc -noq
gltfpack -i "$here/textured_box.glb" -o "$here/textured_box_quantized.glb"
# textured_box_gltf.zip: the box as glTF Transform writes a .gltf (JSON, a .bin and a PNG), with the
# texture moved into textures/ as model sites lay them out, zipped in a folder (a zipped upload).
zipdir="$scratch/zip/textured_box"
rm -rf "$scratch/zip" && mkdir -p "$zipdir/textures"
"$scratch/node_modules/.bin/gltf-transform" copy "$here/textured_box.glb" "$zipdir/textured_box.gltf"
mv "$zipdir/baseColor.png" "$zipdir/textures/baseColor.png"
sed -i -E 's|"uri": *"baseColor.png"|"uri": "textures/baseColor.png"|' "$zipdir/textured_box.gltf"
rm -f "$here/textured_box_gltf.zip"
(cd "$scratch/zip" && python3 -c 'import sys, zipfile
with zipfile.ZipFile(sys.argv[1], "w", zipfile.ZIP_DEFLATED) as z:
    for f in ("textured_box/textured_box.gltf", "textured_box/textured_box.bin", "textured_box/textures/baseColor.png"):
        z.write(f)' "$here/textured_box_gltf.zip")
# textured_box_normalmap_mikk.glb: the Blender box with its checker also as a normal map (a JSON edit),
# then MikkTSpace tangents from glTF Transform's `tangents`: the loader's own tangents must agree.
python3 - "$here/textured_box.glb" "$scratch/normalmap.glb" <<'PY'
import json, struct, sys
b = open(sys.argv[1], 'rb').read()
n = struct.unpack_from('<I', b, 12)[0]
doc, rest = json.loads(b[20:20 + n]), b[20 + n:]
doc['materials'][0]['normalTexture'] = {'index': 0}
j = json.dumps(doc).encode()
j += b' ' * (-len(j) % 4)
open(sys.argv[2], 'wb').write(struct.pack('<III', 0x46546C67, 2, 20 + len(j) + len(rest)) +
                              struct.pack('<II', len(j), 0x4E4F534A) + j + rest)
PY
"$scratch/node_modules/.bin/gltf-transform" tangents "$scratch/normalmap.glb" "$here/textured_box_normalmap_mikk.glb"
