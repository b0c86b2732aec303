-- karst.lua — a karst network under a plateau, cut open (seed 000 §6.2,
-- figures 14 and 17): invasion percolation from the sinks of the
-- plateau's rough top carves tunnels that follow the soft strata. The
-- front of the plateau is cut away by a vertical plane so the tunnels
-- show in the cut face.
--
--   outcrop run examples/karst.lua [--set cell=2] [--seed N] [--out DIR]
--
-- Writes karst.ply (the cut scene's mesh), karst.png (a render of it) and
-- karst_xz.png (a slice through the plateau: the tunnels in cross-section).

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

-- Strata: beds of soft limestone (dark) between harder ones.
local geology = oc.geology.strata{wavelength = 22, octaves = 3, amplitude = 2,
                                  offset = -0.5, seed = 4}
local ground = oc.terrain(hf, {falloff = 8, transition = 1})
local karst, info = oc.generate.karst{heightfield = hf, terrain = ground,
                                      geology = geology, radius = 3.5,
                                      rho0 = 0.7, max_primitives = 12000}
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
print("karst: wrote karst.png, karst_xz.png")
