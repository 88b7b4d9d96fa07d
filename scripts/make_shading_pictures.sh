#!/usr/bin/env bash
# Rebuilds the pictures of docs/SHADING.md with the renderer itself (`pmr render --write views`) and
# scripts/shading_pictures.py (Python standard library only), which crops the views, lays them side
# by side on a grey background and writes 8-bit sRGB PNGs converted exactly as `pmr render --preview`
# converts (checked byte for byte against the renderer's center-view preview of every center view):
#
#   docs/shading_default_scene.png      data/default_scene.glb, center view, --shading lambert | pbr
#                                       (under the studio, the default environment)
#   docs/shading_shadows.png            data/default_scene.glb, center view, --environment uniform (the
#                                       default light), --shadows off | on
#   docs/shading_area_light.png         a floor under a rect area light (made here by shading_pictures.py
#                                       arealight), center view of 9: roughness 0.6 | 0.12
#   docs/shading_penumbra_views.png     the rough one's views 0, N/2 and N-1 of the default 96: the soft
#                                       shadows stay on the floor as the views change
#   docs/shading_suzanne.png            the Khronos sample model Suzanne, center view, lambert | pbr
#   docs/shading_highlight_views.png    a glossy gold sphere (made here by shading_pictures.py sphere),
#                                       views 0, N/2 and N-1 of the default 96, under the default light
#                                       (--environment uniform); the brightest pixel of each view is
#                                       ticked in the margin and printed
#   docs/shading_studio.png             the Khronos sample model AnisotropyStrengthTest, center view,
#                                       pbr with --environment uniform (the default light) | the studio
#   docs/shading_environment_forest.png the same, --environment uniform | Blender's forest.exr
#   docs/shading_glass_views.png        the Khronos sample model GlassHurricaneCandleHolder (transmission
#                                       and volume), views 0, N/2 and N-1 of the default 96, the studio
#   docs/shading_blend.png              the Khronos sample model AlphaBlendModeTest (alphaMode BLEND
#                                       next to OPAQUE and MASK), views 0 and N-1 of 9, the studio
#   docs/shading_variants.png           the Khronos sample model MaterialsVariantsShoe, center view: its
#                                       default materials | --variant midnight | beach | street
#   docs/shading_clearcoat.png          the Khronos sample models ClearCoatTest (center view) and
#                                       ClearCoatCarPaint (views 0 and N-1 of 9), the studio
#   docs/shading_lobes.png              the Khronos sample models SpecularTest and IridescenceSuzanne,
#                                       center views, the studio
#   docs/shading_sheen.png              the Khronos sample model SheenCloth, views 0, N/2 and N-1 of 9,
#                                       the studio
#
# usage: scripts/make_shading_pictures.sh [GLTF_DIR]
#   GLTF_DIR   folder of the Khronos sample models (GLTF_DIR/Suzanne/glTF/Suzanne.gltf, ...); default
#              $PMR_GLTF_DIR, else ../shared/gltf relative to the repository
#   PMR        the renderer (default build/pmr; build it with scripts/setup.sh build)
#   FOREST     the environment image (default Blender's CC0 world HDRI, Debian package blender-data:
#              /usr/share/blender/datafiles/studiolights/world/forest.exr)
#   OUT        where the pictures go (default docs)
# A picture whose input is missing is skipped with a message naming the file, the others are made,
# and the script then exits with status 1. The renders go to a temporary folder that is removed.
# Runs in about half a minute on 2 cores. Not part of the tests or CI.
set -euo pipefail
# paths given by the caller are relative to the caller's folder, the defaults to the repository's
from_caller() { case $1 in /*) echo "$1" ;; *) echo "$PWD/$1" ;; esac; }
GLTF_DIR=$( [ -n "${1:-${PMR_GLTF_DIR:-}}" ] && from_caller "${1:-$PMR_GLTF_DIR}" || echo ../shared/gltf)
PMR=$( [ -n "${PMR:-}" ] && from_caller "$PMR" || echo build/pmr)
FOREST=$(from_caller "${FOREST:-/usr/share/blender/datafiles/studiolights/world/forest.exr}")
OUT=$( [ -n "${OUT:-}" ] && from_caller "$OUT" || echo docs)
cd "$(dirname "$0")/.."
PICTURES="python3 scripts/shading_pictures.py"

[ -x "$PMR" ] || { echo "make_shading_pictures: $PMR not found: build it with scripts/setup.sh build" >&2; exit 1; }
mkdir -p "$OUT"
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
skipped=()
MODELS_HINT="the Khronos sample models are looked for in $GLTF_DIR: give their folder as the first argument"

# render NAME SCENE ARGS...: the views of one run into $WORK/NAME (views file and center preview)
render() {
  local name=$1 scene=$2
  shift 2
  "$PMR" render "$scene" --write views --preview --quiet --out "$WORK/$name" "$@"
}
views() { echo "$WORK/$1/frame_0000.views.exr:$2"; }
center() { echo "$WORK/$1/frame_0000.center.png"; }
present() {  # present FILE PICTURE HINT
  [ -f "$1" ] && return 0
  echo "make_shading_pictures: $1 not found ($3): $2 not rebuilt" >&2
  skipped+=("$2")
  return 1
}

# Views of 166:93 (the display is 166x93 cm: square pixels, so the preview is not resampled and the
# check against it holds byte for byte), 9 views so that view 4 is the center
# camera itself.
pair() {  # pair OUT SCENE VIEW_SIZE: the center view under lambert and pbr
  local out=$1 scene=$2 size=$3
  render lambert "$scene" --views 9 --view-size "$size" --shading lambert
  render pbr "$scene" --views 9 --view-size "$size" --shading pbr
  $PICTURES strip "$out" "$(views lambert 4)" "$(views pbr 4)" --check-center "$(center lambert)" "$(center pbr)"
}

echo "== default scene, lambert | pbr"
pair "$OUT/shading_default_scene.png" data/default_scene.glb 996x558

echo "== default scene under the uniform environment and the default light: --shadows off | on"
render noshadow data/default_scene.glb --views 9 --view-size 996x558 --environment uniform --shadows off
render shadow data/default_scene.glb --views 9 --view-size 996x558 --environment uniform
$PICTURES strip "$OUT/shading_shadows.png" "$(views noshadow 4)" "$(views shadow 4)" \
  --check-center "$(center noshadow)" "$(center shadow)"

echo "== an area light over a rough and a polished floor; the rough one's soft shadows in views 0, 48 and 95 of 96"
$PICTURES arealight "$WORK/rough.glb" 0.6
$PICTURES arealight "$WORK/polished.glb" 0.12
render rough "$WORK/rough.glb" --camera Cam --views 9 --view-size 664x372 --environment uniform
render polished "$WORK/polished.glb" --camera Cam --views 9 --view-size 664x372 --environment uniform
$PICTURES strip "$OUT/shading_area_light.png" "$(views rough 4)" "$(views polished 4)" \
  --check-center "$(center rough)" "$(center polished)"
render penumbra "$WORK/rough.glb" --camera Cam --views 96 --view-size 498x279 --environment uniform
$PICTURES strip "$OUT/shading_penumbra_views.png" "$(views penumbra 0)" "$(views penumbra 48)" "$(views penumbra 95)" \
  --check-center - "$(center penumbra)" -

echo "== Suzanne, lambert | pbr"
SUZANNE=$GLTF_DIR/Suzanne/glTF/Suzanne.gltf
if present "$SUZANNE" "$OUT/shading_suzanne.png" "$MODELS_HINT"; then
  pair "$OUT/shading_suzanne.png" "$SUZANNE" 830x465
fi

echo "== a glossy sphere in views 0, 48 and 95 of 96"
$PICTURES sphere "$WORK/sphere.glb"
render sphere "$WORK/sphere.glb" --views 96 --view-size 498x279 --environment uniform
$PICTURES strip "$OUT/shading_highlight_views.png" "$(views sphere 0)" "$(views sphere 48)" "$(views sphere 95)" --mark \
  --check-center - "$(center sphere)" -

echo "== AnisotropyStrengthTest, uniform and the default light | the studio"
ANISOTROPY=$GLTF_DIR/AnisotropyStrengthTest/glTF-Binary/AnisotropyStrengthTest.glb
if present "$ANISOTROPY" "$OUT/shading_studio.png" "$MODELS_HINT"; then
  render light "$ANISOTROPY" --views 9 --view-size 664x372 --environment uniform
  render studio "$ANISOTROPY" --views 9 --view-size 664x372
  $PICTURES strip "$OUT/shading_studio.png" "$(views light 4)" "$(views studio 4)" \
    --check-center "$(center light)" "$(center studio)"
fi

echo "== AnisotropyStrengthTest, uniform and the default light | forest.exr"
if present "$ANISOTROPY" "$OUT/shading_environment_forest.png" "$MODELS_HINT" &&
   present "$FOREST" "$OUT/shading_environment_forest.png" "set FOREST, or install Debian's blender-data"; then
  render forest "$ANISOTROPY" --views 9 --view-size 664x372 --environment "$FOREST"
  $PICTURES strip "$OUT/shading_environment_forest.png" "$(views light 4)" "$(views forest 4)" \
    --check-center "$(center light)" "$(center forest)"
fi

echo "== GlassHurricaneCandleHolder in views 0, 48 and 95 of 96"
GLASS=$GLTF_DIR/GlassHurricaneCandleHolder/glTF/GlassHurricaneCandleHolder.gltf
if present "$GLASS" "$OUT/shading_glass_views.png" "$MODELS_HINT"; then
  render glass "$GLASS" --views 96 --view-size 498x279
  $PICTURES strip "$OUT/shading_glass_views.png" "$(views glass 0)" "$(views glass 48)" "$(views glass 95)" \
    --check-center - "$(center glass)" -
fi

echo "== AlphaBlendModeTest in views 0 and 8 of 9"
BLEND=$GLTF_DIR/AlphaBlendModeTest/glTF/AlphaBlendModeTest.gltf
if present "$BLEND" "$OUT/shading_blend.png" "$MODELS_HINT"; then
  render blend "$BLEND" --views 9 --view-size 664x372
  $PICTURES strip "$OUT/shading_blend.png" "$(views blend 0)" "$(views blend 8)" --check-center - -
fi

echo "== MaterialsVariantsShoe: its default materials and each variant (KHR_materials_variants)"
SHOE=$GLTF_DIR/MaterialsVariantsShoe/glTF/MaterialsVariantsShoe.gltf
if present "$SHOE" "$OUT/shading_variants.png" "$MODELS_HINT"; then
  panels=() checks=()
  for variant in "" midnight beach street; do
    render "shoe$variant" "$SHOE" --views 9 --view-size 498x279 ${variant:+--variant $variant}
    panels+=("$(views "shoe$variant" 4)") checks+=("$(center "shoe$variant")")
  done
  $PICTURES strip "$OUT/shading_variants.png" "${panels[@]}" --check-center "${checks[@]}"
fi

echo "== ClearCoatTest and ClearCoatCarPaint (KHR_materials_clearcoat)"
COAT=$GLTF_DIR/ClearCoatTest/glTF/ClearCoatTest.gltf
PAINT=$GLTF_DIR/ClearCoatCarPaint/glTF/ClearCoatCarPaint.gltf
if present "$COAT" "$OUT/shading_clearcoat.png" "$MODELS_HINT" &&
   present "$PAINT" "$OUT/shading_clearcoat.png" "$MODELS_HINT"; then
  render coat "$COAT" --views 9 --view-size 498x279
  render paint "$PAINT" --views 9 --view-size 498x279 --zoom 1.6
  $PICTURES strip "$OUT/shading_clearcoat.png" "$(views coat 4)" "$(views paint 0)" "$(views paint 8)" \
    --check-center "$(center coat)" - -
fi

echo "== SpecularTest and IridescenceSuzanne (KHR_materials_specular, KHR_materials_iridescence)"
SPEC=$GLTF_DIR/SpecularTest/glTF/SpecularTest.gltf
IRID=$GLTF_DIR/IridescenceSuzanne/glTF/IridescenceSuzanne.gltf
if present "$SPEC" "$OUT/shading_lobes.png" "$MODELS_HINT" && present "$IRID" "$OUT/shading_lobes.png" "$MODELS_HINT"; then
  render spec "$SPEC" --views 9 --view-size 664x372
  render irid "$IRID" --views 9 --view-size 664x372 --zoom 1.4
  $PICTURES strip "$OUT/shading_lobes.png" "$(views spec 4)" "$(views irid 4)" \
    --check-center "$(center spec)" "$(center irid)"
fi

echo "== SheenCloth (KHR_materials_sheen)"
SHEEN=$GLTF_DIR/SheenCloth/glTF/SheenCloth.gltf
if present "$SHEEN" "$OUT/shading_sheen.png" "$MODELS_HINT"; then
  render sheen "$SHEEN" --views 9 --view-size 498x279 --zoom 1.8
  $PICTURES strip "$OUT/shading_sheen.png" "$(views sheen 0)" "$(views sheen 4)" "$(views sheen 8)" \
    --check-center - "$(center sheen)" -
fi

if [ ${#skipped[@]} -gt 0 ]; then
  echo "make_shading_pictures: NOT rebuilt (inputs missing): ${skipped[*]}" >&2
  exit 1
fi
echo "make_shading_pictures: every picture rebuilt in $OUT"
