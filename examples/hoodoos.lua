-- hoodoos.lua — a field of hoodoos (Paris et al. 2019, figures 18, 19): an
-- amphitheatre rim, a plateau breaking into a talus slope that runs down
-- to a basin, 350 m across. Hoodoos grow where the slope is medium and
-- little water drains (the talus, between the gullies), from the grammar
-- of figure 20: stacked blocks, cones and box caprocks whose widths follow
-- horizontal strata (hard beds make wide caps, soft ones necks).
--
--   outcrop run examples/hoodoos.lua [--set cell=1.2] [--seed N] [--out DIR]
--
-- Writes hoodoos.ply (mesh) and hoodoos.png (render, 800 x 450).

local oc = require "outcrop"
local H, G = oc.heightfield, oc.geology

local cell = oc.param("cell", 1.2)
local size = 350

-- The ground: a plateau 45 m above a basin, its edge a talus band along
-- y = 230 cut by gullies, plus fBm relief.
local relief = H.fbm{size = {131, 131}, cell = 2.7, wavelength = 90,
                     amplitude = 14, octaves = 5, seed = 3}
local ground = H.from(function(x, y)
  local edge = 230 + 18 * math.sin(x / 37) + 9 * math.sin(x / 13 + 1)
  local t = math.max(0, math.min(1, (y - edge + 55) / 85))
  return 45 * t * t * (3 - 2 * t) + relief:height(x, y)
end, {size = {131, 131}, cell = 2.7})
local terrain = oc.terrain(ground)

-- The rock: thin horizontal beds of alternating resistance.
local rock = G.strata{wavelength = 7, octaves = 2, amplitude = 0.9,
                      offset = 0.05, seed = 5}

local scene, info = oc.generate.hoodoos{
  heightfield = ground, terrain = terrain, geology = rock,
  radius = 12, height = {16, 34}, width = 3.4, max_depth = 7, probability = 0.9,
  p_block = 0.55, p_cone = 0.45, roughness = 0.35,
  slope = 0.6, slope_spread = 0.25, drainage = 150}
print(string.format("hoodoos: %d hoodoos, %d primitives (%d blocks, %d " ..
                    "cones, %d caprocks) in %.2f s", info.hoodoos,
                    info.primitives, info.blocks, info.cones, info.boxes,
                    info.seconds))

local x0, y0, z0, x1, y1, z1 = ground:bounds()
local mesh = oc.polygonize(scene, {box = {x0, y0, z0 - 5, x1, y1, z1 + 40},
                                   cell = cell, min_component = 50})
assert(mesh:write("hoodoos.ply"))
local ms = mesh:stats()
print(string.format("hoodoos: wrote hoodoos.ply (%d triangles, %.2f s)",
                    ms.triangles, ms.seconds))

oc.render(scene, {camera = {eye = {175, -60, 75}, target = {175, 200, 35},
                            fov = 42},
                  size = {800, 450}, color = rock,
                  texture = 0,
                  palette = {{0, {0.30, 0.09, 0.03}}, {0.5, {0.52, 0.19, 0.07}},
                             {1, {0.72, 0.48, 0.30}}}}):write("hoodoos.png")
print("hoodoos: wrote hoodoos.png")
