-- sea_cliffs.lua — a sea arch and a sea cave (Paris et al. 2019, §6.1,
-- figure 11): a plateau 25 m high ending in a cliff over the sea, and a
-- headland: a round head 30 m across joined to the cliff by a neck 12 m
-- wide. The rock is horizontally bedded and fairly hard, with a soft
-- pocket in the neck, a hard head and a soft vertical joint in the cliff
-- west of the headland. Eight steps of sea erosion in a 12 m band around
-- sea level notch the cliff where the beds are soft, bore a cave along
-- the joint, and hollow the neck from both sides until the two hollows
-- meet under it: the neck is left as an arch over the sea, the head
-- stands on its own foot.
--
--   outcrop run examples/sea_cliffs.lua [--set cell=0.8] [--set render=false]
--                                       [--seed N] [--out DIR]
--
-- Writes sea_cliffs.ply (mesh coloured by resistance) and, unless
-- render=false, sea_cliffs.png (800 x 450, from the sea west of the neck:
-- the sea and the sky seen through the arch, the head on the right).
-- Run by dofile, it returns {mesh =, scene =, rock =} (the topology test,
-- tests/runtime/examples.sh, reads the mesh so).

local oc = require "outcrop"
local H, G = oc.heightfield, oc.geology

local cell = oc.param("cell", 0.8)
local picture = oc.param("render", true)

-- The coast: sea floor at -12 m, a cliff along y = 90 (wavy), the plateau
-- at 25 m. The headland around x = 150 is lower (about 14 m): its
-- half-width at mid-height is w(y), a circle of radius 15 about y = 57
-- (the head, tip at y = 42) widened to 6 from there to the cliff (the
-- neck).
local relief = H.fbm{size = {301, 201}, cell = 1, wavelength = 60,
                     amplitude = 6, octaves = 4, seed = 4}
local function smooth(t) t = math.max(0, math.min(1, t)); return t * t * (3 - 2 * t) end
local HX, HY, HR, NECK = 150, 57, 15, 6
local ground = H.from(function(x, y)
  local edge = 90 + 6 * math.sin(x / 23)
  local land = smooth((y - edge + 5) / 10)
  local d2 = HR * HR - (y - HY) ^ 2
  local w = d2 > 0 and math.sqrt(d2) or -10
  if y > HY and y < edge + 5 then w = math.max(w, NECK) end
  local head = smooth((w - math.abs(x - HX)) / 6 + 0.5)
  local r = relief:height(x, y)
  return math.max(-12 + (37 + r) * land, -12 + (25 + 0.5 * r) * head)
end, {size = {301, 201}, cell = 1})
local terrain = oc.terrain(ground)

-- The rock: beds of resistance 0.6 to 1.2, a soft pocket in the neck
-- (where the sea breaks through), a hard head (so that its foot stands)
-- and a soft joint across the cliff at x = 122 (the sea cave).
local rock = G.strata{wavelength = 6, octaves = 3, amplitude = 0.6, offset = 0.6, seed = 2}
  + G.sphere{center = {HX, 78, 1}, radius = 7, falloff = 5, resistance = -0.9}
  + G.sphere{center = {HX, HY, 0}, radius = HR - 4, falloff = 4, resistance = 1.5}
  + G.layer{origin = {122, 92, 0}, normal = {1, 0.3, 0}, radius = 2.5, resistance = -0.8}

-- A low strength and beta make the bite depend on the rock: on hard rock
-- even the sum of the overlapping primitives stays above the surface.
local scene, info = oc.generate.sea{heightfield = ground, terrain = terrain,
                                    geology = rock, sea_level = 0, range = 12,
                                    radius = 6, spacing = 1.5, strength = 0.8,
                                    beta = 0.05, steps = 8}
print(string.format("sea_cliffs: %d columns, %d samples, %d primitives",
                    info.columns, info.samples, info.primitives))

-- colours: resistance clamped to [0, 1], dark where soft
local shade = G.clamp(rock)
local palette = {{0.6, {0.30, 0.20, 0.13}}, {0.85, {0.55, 0.42, 0.30}},
                 {1.0, {0.78, 0.70, 0.58}}}
local mesh = oc.polygonize(scene, {box = {0, 0, -14, 300, 200, 60}, cell = cell,
                                   colors = {field = shade, palette = palette},
                                   min_component = 50})
assert(mesh:write("sea_cliffs.ply"))
local ms = mesh:stats()
print(string.format("sea_cliffs: wrote sea_cliffs.ply (%d triangles, %.2f s)",
                    ms.triangles, ms.seconds))
local result = {mesh = mesh, scene = scene, rock = rock}
if not picture then return result end

-- For the picture only: the sea as a slab whose surface lies 1.5 m under
-- sea level (so the foot of the arch stays in view), coloured blue through
-- a colour field that adds 4 in the water.
local water = oc.box{min = {-10, -10, -20}, max = {310, 210, -1.5}, falloff = 0.5}
local wet = oc.box{min = {-10, -10, -20}, max = {310, 210, -0.5}, falloff = 0.1,
                   energy = 4}
local rpal = {{0.6, {0.30, 0.20, 0.13}}, {0.85, {0.55, 0.42, 0.30}},
              {1.0, {0.78, 0.70, 0.58}}, {1.5, {0.78, 0.70, 0.58}},
              {1.9, {0.10, 0.25, 0.35}}, {6.0, {0.10, 0.25, 0.35}}}
oc.render(oc.union{scene, water},
          {camera = {eye = {105, 77, 1.5}, target = {150, 80, 4}, fov = 38},
           sun = {direction = {-0.6, -0.5, 0.55}, intensity = 1.4},
           size = {800, 450}, color = shade + wet, palette = rpal}):write("sea_cliffs.png")
print("sea_cliffs: wrote sea_cliffs.png")
return result
