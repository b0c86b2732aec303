-- elev_river.lua — a river carved into hills, the construction tree of
-- Génevaux et al. 2015, figure 3: a covering base disc, hill discs
-- blended with it, and a river (outcrop.elevation.river, kind "river")
-- replaced in. The river's points carry its bank level, falling from
-- 40 m where it enters in the north-west to 4 m where it leaves in the
-- south-east, so it flows downhill; the replacement lowers a valley to
-- that bed through whatever hill stands in its way. Traced directly (no
-- heightfield, no mesh); the channel is coloured as water from the
-- river's own weight (1 over the channel).
--
--   outcrop run examples/elev_river.lua [--set size=640] [--out DIR]
--
-- (640 x 360 by default, about 30 s of CPU: the direct tracer takes
-- about 50 tree calls per pixel on these noisy discs; size=1280 gives
-- the 1280 x 720 picture in four times as long.)

local oc = require "outcrop"
local E = oc.elevation

local w = oc.param("size", 640)
local h = w * 9 // 16

-- 1 x 1 km around the origin. A disc's terrain (alpha >= 1/2) reaches
-- 0.4542 of its radius, so a base of radius 1600 m covers the square's
-- corners (707 m). Its noise is the ground's texture; on the hills it is
-- averaged with theirs.
local base = E.disc{center = {0, 0}, radius = 1600, height = 30,
                    noise = {amplitude = 25, wavelength = 350, octaves = 5,
                             gain = 0.45, seed = 1}}

-- Hills on both sides of the valley, two across its path so that the
-- river has something to cut through: {x, y, radius, height}.
local hills = {
  {-380, 380, 420, 170}, {60, 430, 450, 195}, {430, 250, 400, 155},
  {-450, -80, 380, 140}, {-200, -420, 440, 180}, {220, -400, 430, 175},
  {500, -180, 360, 135}, {20, 40, 300, 140},
}
local parts = {base}
for i, d in ipairs(hills) do
  parts[#parts + 1] = E.disc{center = {d[1], d[2]}, radius = d[3], height = d[4],
    noise = {kind = i % 2 == 0 and "turbulence" or "plain", amplitude = 0.11 * d[4],
             wavelength = 0.6 * d[3], octaves = 3, gain = 0.4, seed = 10 + i}}
end
local land = E.blend(parts)

-- The river, north-west to south-east past the square's edges, its bank
-- level falling along it; a 24 m channel 3 m deep, banks 110 m wide.
local river = E.river{kind = "river", width = 24, depth = 3, bank = 110, points = {
  {-950, 420, 40}, {-560, 330, 34}, {-250, 150, 27}, {0, -60, 20},
  {280, -150, 13}, {600, -300, 8}, {950, -360, 4}}}
local scene = E.replace(land, river)

local st = scene:stats()
print(("elev_river: %d nodes, %d primitives, %d bytes; Lipschitz bound %.1f")
      :format(st.nodes, st.primitives, st.bytes, scene:lipschitz()))

-- Albedos (linear, as the renderer's rules): water in the channel, grass
-- on gentle slopes, rock on steep ones (the valley's cut sides).
local function colour(x, y, z, nx, ny, nz)
  local _, a = river:eval(x, y)
  if a >= 0.999 then return 0.03, 0.07, 0.10 end
  local rock = math.min(1, math.max(0, (0.9 - nz) / 0.1))
  return 0.10 + 0.12 * rock, 0.17 + 0.01 * rock, 0.05 + 0.10 * rock
end

local t = os.clock()
local img = oc.render(scene, {
  size = {w, h},
  camera = {eye = {950, -1000, 700}, target = {-80, 80, 40}, fov = 40},
  color = colour,
})
assert(img:write("elev_river.png"))
print(("elev_river: wrote elev_river.png (%.1f s of CPU)"):format(os.clock() - t))
