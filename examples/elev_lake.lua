-- elev_lake.lua — a lake in hills, as Génevaux et al. 2015, figure 7:
-- hill discs blended over a covering base, and a lake (the contour
-- primitive, outcrop.elevation.lake) replaced in: a shore through eight
-- radii around a centre, its water level below the surrounding hills.
-- The lake's profile is the water surface inside the shore (flat, at the
-- level) and a bank rising 6 m over the 70 m outside it, where the lake's
-- weight falls to 0 and the replacement blends the bank into the hills.
--
--   outcrop run examples/elev_lake.lua [--set size=640] [--out DIR]

local oc = require "outcrop"
local E = oc.elevation

local w = oc.param("size", 640)
local h = w * 9 // 16

-- 1.2 x 1.2 km around the origin: a base of radius 1900 m reaches
-- 0.4542 x 1900 = 863 m, past the corners (849 m).
local base = E.disc{center = {0, 0}, radius = 1900, height = 40,
                    noise = {amplitude = 10, wavelength = 300, octaves = 4,
                             gain = 0.45, seed = 71}}
-- Hills in a ring around the basin: {x, y, radius, height}.
local hills = {
  {-420, 300, 520, 300}, {130, 470, 460, 340}, {520, 200, 430, 280},
  {480, -330, 480, 320}, {-80, -480, 500, 250}, {-520, -220, 420, 260},
}
local parts = {base}
for i, d in ipairs(hills) do
  parts[#parts + 1] = E.disc{center = {d[1], d[2]}, radius = d[3], height = d[4],
    noise = {kind = i % 2 == 0 and "turbulence" or "plain", amplitude = 0.12 * d[4],
             wavelength = 0.6 * d[3], octaves = 3, gain = 0.4, seed = 80 + i}}
end
local land = E.blend(parts)

-- The lake: a shore through eight radii (equal angles from +x), its
-- level 10 m above the basin floor and well below the hills around it.
local level = 70
local lake = E.lake{center = {0, 0}, radius = {230, 270, 200, 250, 190, 260, 210, 240},
                    level = level, falloff = 70,
                    profile = {{-30, 0}, {0, 0}, {20, 1.5}, {70, 6}}}
local scene = E.replace(land, lake)

local st = scene:stats()
print(("elev_lake: %d nodes, %d primitives, %d bytes; Lipschitz bound %.1f")
      :format(st.nodes, st.primitives, st.bytes, scene:lipschitz()))
-- the level against the land around it: the lowest and highest point of
-- the land on a circle 120 m outside the shore's largest radius
local lo, hi = math.huge, -math.huge
for k = 0, 359 do
  local a = math.rad(k)
  local f = land:eval(390 * math.cos(a), 390 * math.sin(a))
  lo, hi = math.min(lo, f), math.max(hi, f)
end
print(("elev_lake: water level %.1f m; the land 390 m from the centre %.1f to %.1f m")
      :format(level, lo, hi))

-- Albedos (linear): water where the lake's weight is 1 and the surface
-- at its level, grass, rock on steep slopes, a pale beach on the bank.
local function colour(x, y, z, nx, ny, nz)
  local _, a = lake:eval(x, y)
  if a >= 0.999 and z <= level + 0.01 then return 0.03, 0.07, 0.10 end
  if a > 0.3 and z <= level + 2 then return 0.35, 0.32, 0.24 end
  local rock = math.min(1, math.max(0, (0.85 - nz) / 0.1))
  return 0.10 + 0.12 * rock, 0.17 + 0.01 * rock, 0.05 + 0.10 * rock
end

local t = os.clock()
local img = oc.render(scene, {
  size = {w, h},
  camera = {eye = {-760, -980, 560}, target = {0, 0, 60}, fov = 40},
  color = colour,
})
assert(img:write("elev_lake.png"))
print(("elev_lake: wrote elev_lake.png (%.1f s of CPU)"):format(os.clock() - t))
