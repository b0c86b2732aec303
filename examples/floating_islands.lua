-- floating_islands.lua — islands in the sky (seed 000 figures 1 and 21):
-- each island is the intersection of a terrain (its top: solid below a
-- heightfield) and an inverted terrain (its underside: solid above a
-- second heightfield), cut to an island shape by a mask.
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

local sky = oc.union(islands)
local mesh = oc.polygonize(sky, {box = {-half, -half, 20, half, half, 200},
                                 cell = cell})
mesh:write("floating_islands.ply")
local st = mesh:stats()
print(string.format("floating_islands: %d triangles in %.2f s", st.triangles,
                    st.seconds))
oc.render(sky, {camera = {eye = {-250, -230, 200}, target = {20, -10, 105},
                          fov = 40},
                size = {960, 540}}):write("floating_islands.png")
print("floating_islands: wrote floating_islands.ply, floating_islands.png")
