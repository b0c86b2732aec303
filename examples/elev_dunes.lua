-- elev_dunes.lua — dunes added to a mountainous desert below an altitude,
-- as Génevaux et al. 2015, figure 13: a flat desert floor (a covering base
-- disc) and a range of rocky mountains blended with it, then a dune field
-- (a disc of ridged noise, 130 m wavelength) added over the whole scene
-- with outcrop.elevation.add(land, dunes, {below = 45, fade = 25}): the
-- dunes' weight is 1 where the land is below 20 m, fades to 0 at 45 m,
-- so sand fills the low ground and the mountains' flanks stay bare rock.
--
--   outcrop run examples/elev_dunes.lua [--set size=640] [--out DIR]

local oc = require "outcrop"
local E = oc.elevation

local w = oc.param("size", 640)
local h = w * 9 // 16
local below, fade = 45, 25

-- 1.2 x 1.2 km. The base disc's terrain reaches 0.4542 x 2000 = 908 m
-- from the origin, past the square's corners (849 m).
local floor = E.disc{center = {0, 0}, radius = 2000, height = 8,
                     noise = {amplitude = 6, wavelength = 400, octaves = 2, seed = 3}}

-- The range along the north-east: {x, y, radius, height}.
local peaks = {
  {250, 420, 380, 330}, {-150, 520, 330, 280}, {520, 120, 330, 260},
  {560, 520, 300, 300},
}
local parts = {floor}
for i, d in ipairs(peaks) do
  parts[#parts + 1] = E.disc{center = {d[1], d[2]}, radius = d[3], height = d[4],
    noise = {kind = "turbulence", amplitude = 0.3 * d[4], wavelength = 0.7 * d[3],
             octaves = 3, gain = 0.4, seed = 20 + i}}
end
local land = E.blend(parts)

-- The dune field: crests of ridged noise around 0 m, over everything; the
-- add keeps the land's weight, so the dunes only raise the ground.
local dunes = E.disc{center = {0, 0}, radius = 2000,
                     noise = {kind = "ridged", amplitude = 12, wavelength = 130,
                              octaves = 2, gain = 0.3, seed = 7}}
local scene = E.add(land, dunes, {below = below, fade = fade})

local st = scene:stats()
print(("elev_dunes: %d nodes, %d primitives, %d bytes; Lipschitz bound %.1f")
      :format(st.nodes, st.primitives, st.bytes, scene:lipschitz()))
-- the dunes change the ground only below the altitude
local f0 = land:eval(-300, -300)
local f1 = scene:eval(-300, -300)
local g0 = land:eval(250, 420)
local g1 = scene:eval(250, 420)
print(("elev_dunes: desert floor %.1f m -> %.1f m with dunes; peak %.1f m -> %.1f m")
      :format(f0, f1, g0, g1))

-- Albedos (linear): sand on the low ground, rock above, blended over the
-- fade band.
local function colour(x, y, z, nx, ny, nz)
  local s = math.min(1, math.max(0, (below + 10 - z) / fade))
  return 0.22 + 0.18 * s, 0.17 + 0.15 * s, 0.13 + 0.08 * s
end

local t = os.clock()
local img = oc.render(scene, {
  size = {w, h},
  camera = {eye = {-650, -800, 330}, target = {120, 200, 60}, fov = 40},
  sun = {direction = {-0.7, 0.2, 0.45}},
  color = colour,
})
assert(img:write("elev_dunes.png"))
print(("elev_dunes: wrote elev_dunes.png (%.1f s of CPU)"):format(os.clock() - t))
