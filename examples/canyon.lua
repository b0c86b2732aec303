-- canyon.lua — a river canyon with undercut walls (Paris et al. 2019, figure 15):
-- a plateau of horizontally bedded rock cut by a meandering canyon whose
-- floor slopes downstream. River erosion reads the stream power of the
-- heightfield: the riverbed (high stream power) and its banks are carved
-- by negative spheres, deepest in the soft beds, so the walls are undercut
-- where the strata are soft and stand out as ledges where they are hard.
--
--   outcrop run examples/canyon.lua [--set cell=0.8] [--seed N] [--out DIR]
--
-- Writes canyon.ply (mesh coloured by resistance) and canyon.png (render,
-- 800 x 450).

local oc = require "outcrop"
local H, G = oc.heightfield, oc.geology

local cell = oc.param("cell", 0.8)

-- The plateau at 50 m, a canyon 40 m deep meandering along y, its floor
-- falling from 12 m to 4 m downstream, walls steepening towards the rim.
local relief = H.fbm{size = {201, 201}, cell = 1.5, wavelength = 50,
                     amplitude = 4, octaves = 4, seed = 8}
local function smooth(t) t = math.max(0, math.min(1, t)); return t * t * (3 - 2 * t) end
local ground = H.from(function(x, y)
  local cx = 150 + 35 * math.sin(y / 45) + 10 * math.sin(y / 17)
  local d = math.abs(x - cx)
  local floor = 12 - 8 * y / 300
  local wall = smooth((d - 9) / 16)
  return floor + (50 - floor) * wall + relief:height(x, y) * wall
end, {size = {201, 201}, cell = 1.5})
local terrain = oc.terrain(ground)

-- Beds 5 m thick of alternating resistance, and one soft bed above the floor.
local rock = G.strata{wavelength = 5, octaves = 3, amplitude = 0.7, offset = 0.3, seed = 6}
  + G.layer{origin = {0, 0, 16}, normal = {0, 0, 1}, radius = 3, resistance = -0.4}

local scene, info = oc.generate.river{heightfield = ground, terrain = terrain,
                                      geology = rock, radius = 5, spacing = 1.6,
                                      banks = 4, depth = 16, strength = 1.6,
                                      steps = 2}
print(string.format("canyon: %d columns, %d samples, %d primitives",
                    info.columns, info.samples, info.primitives))

local palette = {{0.0, {0.45, 0.20, 0.10}}, {0.5, {0.66, 0.38, 0.22}},
                 {1.0, {0.85, 0.70, 0.52}}}
local mesh = oc.polygonize(scene, {box = {0, 0, -5, 300, 300, 60}, cell = cell,
                                   colors = {field = rock, palette = palette},
                                   -- loose specks of a few vertices dropped
                                   min_component = 50})
assert(mesh:write("canyon.ply"))
local ms = mesh:stats()
print(string.format("canyon: wrote canyon.ply (%d triangles, %.2f s)",
                    ms.triangles, ms.seconds))

oc.render(scene, {camera = {eye = {178, 15, 85}, target = {160, 165, 5}, fov = 45},
                  size = {800, 450}, color = rock, palette = palette,
                  sun = {direction = {0.4, -0.3, 0.8}, intensity = 1.6}}):write("canyon.png")
print("canyon: wrote canyon.png")
