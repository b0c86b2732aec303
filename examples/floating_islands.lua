-- floating_islands.lua — islands in the sky (Paris et al. 2019, figures 1 and 21):
-- each island is the intersection of a terrain (its top: solid below a
-- heightfield) and an inverted terrain (its underside: solid above a
-- second heightfield), cut to an island shape by a mask, then eroded
-- through folded strata so that soft beds recede into ledges.
--
--   outcrop run examples/floating_islands.lua [--set cell=1.5] [--out DIR]

local oc = require "outcrop"
local H = oc.heightfield

local cell = oc.param("cell", 1.5)
local size, step = 161, 2 -- samples per side, metres between samples
local half = (size - 1) * step / 2

-- Island masks: 1 inside a wobbly disc, 0 outside.
local function disc(cx, cy, r)
  return function(x, y)
    local dx, dy = x - cx, y - cy
    local a = math.atan(dy, dx)
    local rr = r * (1 + 0.12 * math.sin(3 * a) + 0.07 * math.cos(5 * a + 1))
    return (dx * dx + dy * dy <= rr * rr) and 1 or 0
  end
end

local islands = {}
local function island(cx, cy, r, z, seed)
  local grid = {size = {size, size}, cell = step, origin = {-half, -half}}
  local top = H.fbm{size = grid.size, cell = step, origin = grid.origin,
                    wavelength = 60, amplitude = 14, octaves = 5, seed = seed}
  -- the top: the fBm raised to z, domed towards the centre
  top = H.from(function(x, y)
    local d = math.sqrt((x - cx) ^ 2 + (y - cy) ^ 2) / r
    return z + top:height(x, y) - 6 * d * d
  end, grid)
  -- the underside: a cone hanging below, roughened
  local rough = H.fbm{size = grid.size, cell = step, origin = grid.origin,
                      wavelength = 25, amplitude = 8, octaves = 4,
                      seed = seed + 100}
  local under = H.from(function(x, y)
    local d = math.sqrt((x - cx) ^ 2 + (y - cy) ^ 2) / r
    return z - 45 * math.max(0, 1 - d) + 4 + rough:height(x, y)
  end, grid)
  local mask = H.from(disc(cx, cy, r), grid)
  local upper = oc.terrain(top, {falloff = 4, transition = 1.5, mask = mask,
                                   thickness = 60})
  local lower = oc.terrain(under, {falloff = 4, transition = 1.5, mask = mask,
                                   invert = true, thickness = 60})
  islands[#islands + 1] = oc.intersection{upper, lower}
end
island(-60, -40, 70, 120, 3)
island(90, 70, 55, 150, 7)
island(100, -110, 40, 95, 11)

-- The rock: folded strata with a soft bed; erosion eats (1 - resistance)
-- of `depth` everywhere, so hard beds stand out as ledges on the flanks.
local G = oc.geology
local rock = G.fold(G.strata{wavelength = 7, amplitude = 0.8, offset = 0.1,
                             seed = 4}
                    + G.layer{origin = {0, 0, 100}, normal = {0, 0.2, 1},
                              radius = 3, resistance = -0.4},
                    {wavelength = 60, amplitude = 6, seed = 9})
local sky = oc.erosion(oc.union(islands), rock, {depth = 0.45})
local mesh = oc.polygonize(sky, {box = {-half, -half, 20, half, half, 200},
                                 cell = cell})
mesh:write("floating_islands.ply")
local st = mesh:stats()
print(string.format("floating_islands: %d triangles in %.2f s", st.triangles,
                    st.seconds))
oc.render(sky, {camera = {eye = {-190, -185, 165}, target = {-20, -25, 100},
                          fov = 40},
                size = {800, 450},
                color = rock,
                palette = {{0, {0.13, 0.07, 0.04}}, {0.5, {0.30, 0.20, 0.12}},
                           {1, {0.55, 0.47, 0.36}}}}):write("floating_islands.png")
print("floating_islands: wrote floating_islands.ply, floating_islands.png")
