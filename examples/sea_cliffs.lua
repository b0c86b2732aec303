-- sea_cliffs.lua — sea cliffs with an arch and a sea cave (seed 000
-- figure 11): a plateau 25 m high ending in a cliff over the sea, with a
-- headland sticking out. The rock is horizontally bedded, with a soft bed
-- at sea level and a soft pocket in the headland; four steps of sea
-- erosion in an 8 m band around sea level undercut the cliff, hollow a
-- sea cave along the soft bed and punch an arch through the headland.
--
--   outcrop run examples/sea_cliffs.lua [--set cell=0.8] [--seed N] [--out DIR]
--
-- Writes sea_cliffs.ply (mesh coloured by resistance) and sea_cliffs.png
-- (render, 800 x 450).

local oc = require "outcrop"
local H, G = oc.heightfield, oc.geology

local cell = oc.param("cell", 0.8)

-- The coast: sea floor at -12 m, a cliff along y = 90 (wavy), the plateau
-- at 25 m, and a narrow headland reaching out to y = 52 around x = 150.
local relief = H.fbm{size = {301, 201}, cell = 1, wavelength = 60,
                     amplitude = 6, octaves = 4, seed = 4}
local function smooth(t) t = math.max(0, math.min(1, t)); return t * t * (3 - 2 * t) end
local ground = H.from(function(x, y)
  local edge = 90 + 6 * math.sin(x / 23)
  edge = edge - 38 * math.exp(-((x - 150) / 10) ^ 2) -- the headland
  local land = smooth((y - edge + 5) / 10)
  return -12 + 37 * land + relief:height(x, y) * land
end, {size = {301, 201}, cell = 1})
local terrain = oc.terrain(ground)

-- The rock: beds of alternating resistance, a soft bed at sea level and a
-- soft pocket in the headland, where the arch will open.
local rock = G.strata{wavelength = 6, octaves = 3, amplitude = 0.6, offset = 0.35, seed = 2}
  + G.layer{origin = {0, 0, 1}, normal = {0, 0, 1}, radius = 4, resistance = -0.6}
  + G.sphere{center = {150, 66, 2}, radius = 7, falloff = 5, resistance = -0.9}

local scene, info = oc.generate.sea{heightfield = ground, terrain = terrain,
                                    geology = rock, sea_level = 0, range = 8,
                                    radius = 6, spacing = 1.5, strength = 6, steps = 4}
print(string.format("sea_cliffs: %d columns, %d samples, %d primitives",
                    info.columns, info.samples, info.primitives))

local palette = {{0.0, {0.30, 0.20, 0.13}}, {0.5, {0.55, 0.42, 0.30}},
                 {1.0, {0.78, 0.70, 0.58}}}
local mesh = oc.polygonize(scene, {box = {0, 0, -14, 300, 200, 60}, cell = cell,
                                   colors = {field = rock, palette = palette}})
assert(mesh:write("sea_cliffs.ply"))
local ms = mesh:stats()
print(string.format("sea_cliffs: wrote sea_cliffs.ply (%d triangles, %.2f s)",
                    ms.triangles, ms.seconds))

-- For the picture only: the sea as a slab whose surface lies 2 m under sea
-- level (so the notch stays in view), coloured blue through a colour field
-- that adds 4 in the water.
local water = oc.box{min = {-10, -10, -20}, max = {310, 210, -2.5}, falloff = 0.5}
local wet = oc.box{min = {-10, -10, -20}, max = {310, 210, -1.5}, falloff = 0.1,
                   energy = 4}
local rpal = {{0.0, {0.30, 0.20, 0.13}}, {0.5, {0.55, 0.42, 0.30}},
              {1.0, {0.78, 0.70, 0.58}}, {1.5, {0.78, 0.70, 0.58}},
              {1.9, {0.10, 0.25, 0.35}}, {6.0, {0.10, 0.25, 0.35}}}
oc.render(oc.union{scene, water},
          {camera = {eye = {112, 30, 6}, target = {150, 64, 1}, fov = 55},
           sun = {direction = {-0.6, -0.5, 0.55}, intensity = 1.4},
           size = {800, 450}, color = rock + wet, palette = rpal}):write("sea_cliffs.png")
print("sea_cliffs: wrote sea_cliffs.png")
