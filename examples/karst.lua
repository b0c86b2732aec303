-- karst.lua — a karst network under a plateau, cut open (Paris et al. 2019, §6.2,
-- figures 14 and 17): invasion percolation from the sinks of the
-- plateau's rough top carves tunnels that follow the soft strata. The
-- front of the plateau is cut away by a vertical plane so the tunnels
-- show in the cut face.
--
--   outcrop run examples/karst.lua [--set cell=2] [--seed N] [--out DIR]
--
-- Writes karst.ply (the cut scene's mesh), karst.png (a render of it),
-- karst_xz.png (a slice through the plateau: the tunnels in cross-section)
-- and karst_network.png (the cavities alone, drawn as a solid).

local oc = require "outcrop"

local cell = oc.param("cell", 2)
local n, h = 201, 2 -- 400 x 400 m
local rough = oc.heightfield.fbm{size = {n, n}, cell = h, wavelength = 60,
                                 amplitude = 6, octaves = 5, seed = 3}
local c = (n - 1) * h / 2
local hf = oc.heightfield.from(function(x, y)
  local r = math.sqrt((x - c) ^ 2 + (y - c) ^ 2) / 170
  local t = math.max(0, math.min(1, (r - 0.7) / 0.3))
  local s = 1 - t * t * (3 - 2 * t)
  return 10 + 70 * s + rough:height(x, y) * (0.3 + 0.7 * s)
end, {size = {n, n}, cell = h})

-- The rock: hard strata, two soft beds (z = 30 and 50) and two soft
-- vertical fractures crossing under the plateau; water sinks down the
-- fractures from the pits of the top and spreads along the soft beds.
local G = oc.geology
local geology = G.strata{wavelength = 30, octaves = 2, amplitude = 0.5,
                         offset = 0.45, seed = 4}
  + G.layer{origin = {0, 0, 50}, normal = {0, 0, 1}, radius = 2, resistance = -0.6}
  + G.layer{origin = {0, 0, 30}, normal = {0, 0, 1}, radius = 2, resistance = -0.6}
  + G.layer{origin = {c, c, 0}, normal = {1, 0.4, 0}, radius = 2, resistance = -0.6}
  + G.layer{origin = {c, c, 0}, normal = {-0.3, 1, 0}, radius = 2, resistance = -0.6}
local ground = oc.terrain(hf, {falloff = 8, transition = 1})
local options = {heightfield = hf, terrain = ground, geology = geology,
                 radius = 2.5, rho0 = 0.5, max_primitives = 20000}
local karst, info = oc.generate.karst(options)
print(string.format("karst: %d sinks, %d cavities in %.2f s", info.sinks,
                    info.primitives, info.seconds))

-- Cut the front half away (y < c) so the tunnels open on the cut face.
local cut = karst & oc.plane{origin = {0, c, 0}, normal = {0, -1, 0}, falloff = 1}
local box = {4, c - 2, 0, 396, 396, 95}
local mesh = oc.polygonize(cut, {box = box, cell = cell})
assert(mesh:write("karst.ply"))
print(string.format("karst: wrote karst.ply (%d triangles)", mesh:stats().triangles))

oc.render(cut, {camera = {eye = {150, -120, 150}, target = {200, 200, 35}, fov = 40},
                size = {800, 450}, color = geology}):write("karst.png")
oc.slice(karst, {plane = "xz", at = c, box = {0, 0, 400, 100},
                 size = {800, 200}}):write("karst_xz.png")
-- The network alone, as a solid: the cavities negated.
options.terrain = false
local cavities = oc.generate.karst(options)
oc.render(-cavities, {camera = {eye = {10, -60, 150}, target = {200, 200, 35},
                                fov = 30},
                      size = {800, 450}}):write("karst_network.png")
print("karst: wrote karst.png, karst_xz.png, karst_network.png")
