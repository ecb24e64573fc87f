#!/usr/bin/env bash
# Re-renders the README's pictures (docs/images/*.png) from the shipped scenes, at 800×600 or
# more, with the sample and wavelength counts that make each one converge (no speckle). Run it
# whenever the renderer changes what a picture shows; it takes long on a CPU-only machine (each
# line prints its own progress). Usage:
#   scripts/render_pictures.sh [NAME...]     (default: every picture; NAME = a scene's base name)
# Environment: EIKON (default build/apps/eikon), EIKON_PICTURE_ARGS (extra arguments for every
# render, e.g. "--reference" to use the CPU twin where it is the faster).
set -euo pipefail
cd "$(dirname "$0")/.."
EIKON="${EIKON:-build/apps/eikon}"
[[ -x "$EIKON" ]] || { echo "render_pictures: error: $EIKON not built (run ./scripts/build.sh)" >&2; exit 1; }

# name | width×height | extra arguments (the scene's own aspect ratio, at least 800×600). The
# samples, wavelengths and exposure of each picture are the scene's own "render" settings
# (docs/scene-format.md), so that `eikon render scenes/NAME.json` alone gives its picture.
# Spectral scenes use 16 wavelengths per sample (the default), by hero sampling where the
# path weights do not depend on λ (docs/spectra.md): one wavelength carries a sample past the
# first dispersive facet, so the jittered samples per pixel are what take the colour noise out
# (the diamond's small bright lights need 64; the prism's narrow slit, seen through the prism in
# every pixel, needs hundreds: 512 still leave a fine grain in its violet). prism_rainbow renders
# its view in RGB (--wavelengths 0): its colours are the light simulation's 12 bands (the beam
# in the haze, the spectrum on the floor), which an RGB view shows too (its reds ~15% darker
# than a spectral view's); a spectral view of this scene marches 16 stratified wavelengths (it
# attenuates: no hero sampling), 16x the cost, and still leaves colour grain on its grey
# background at 4 samples (σ ≈ 15% at 200×150).
# On lavapipe (2 cores) the CPU twin (EIKON_PICTURE_ARGS=--reference) is the faster for
# tourmaline, prism_bk7 and smoke_sphere; lavapipe for caustic_sphere and prism_rainbow (241 s
# against 279 s), but there lavapipe cuts 5 samples short at its loop limit and draws the prism's
# edge lines fainter than the twin does, so that picture is the twin's.
pictures=(
  "glass_sphere|800x600|"
  "prism_bk7|800x600|"
  "diamond_brilliant|800x600|"
  "faceted_round_brilliant|800x600|"
  "faceted_emerald_cut|800x600|"
  "faceted_oval|800x600|"
  "faceted_pear|800x600|"
  # A coloured stone: attenuation makes the spectral passes stratified (every wavelength marched per
  # sample), so 16 samples of 8 wavelengths converge its colour.
  "faceted_oval_ruby|800x600|"
  # A biaxial stone: both modes marched, spectral.
  "biaxial_chrysoberyl|800x600|"
  # The oval's fire on a table: the light through its sharp facets in 12 bands (~50 s), then the
  # view; 32 samples take the grain off the table and the spots in the shadow.
  "faceted_oval_fire|800x600|"
  "mesh_icosphere|800x600|"
  "mesh_torus|800x600|"
  # The ring lit over a table (the light through its triangles, ~15 s, then the view): 32 samples
  # converge the table (128 change it by 0.13 of 255 on average); the ring's glitter is its
  # facets' images, the same at 128 samples.
  "mesh_torus_caustic|800x600|"
  # calcite_rhomb: crossings on the shapes (BoundaryField::exact), so the ink lines' edges are
  # straight at any size; 8 samples take the hero sampling's colour grain off the paper.
  "calcite_rhomb|800x600|"
  "tourmaline|800x600|"
  "caustic_sphere|800x600|"
  "prism_rainbow|960x600|"
  "smoke_sphere|960x600|"
  # Polarised (polariser sheets): deterministic, so 1 sample (the pixel centres). The conoscope
  # and the gems in monochromatic light (RGB mode: one trace per pixel at 587.56 nm; a quartz
  # brilliant's retardation is of high order, white in white light anyway), the wedge at 32
  # wavelengths per pixel, at one sample the 32 bins' centres for every pixel (no colour grain;
  # fewer bins miss the third order's period). The CPU twin (--reference) renders them.
  "conoscope_calcite|800x600|"
  "conoscope_aragonite|800x600|--transport single"
  "polariscope_gems_0|800x600|--reference"
  "polariscope_gems_45|800x600|--reference"
  "polariscope_quartz_wedge|800x600|--reference"
)

want=("$@")
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
for entry in "${pictures[@]}"; do
  IFS='|' read -r name size args <<<"$entry"
  if ((${#want[@]})) && [[ ! " ${want[*]} " =~ " $name " ]]; then continue; fi
  echo "== $name ($size, $args)"
  # shellcheck disable=SC2086
  "$EIKON" render "scenes/$name.json" -o "$out/$name.exr" --width "${size%x*}" \
    --height "${size#*x}" $args \
    ${EIKON_PICTURE_ARGS:-}
  mv "$out/$name.png" "docs/images/$name.png"
done
