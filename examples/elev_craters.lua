-- elev_craters.lua — lunar craters by replacement, the order of the tree
-- the order of time (Génevaux et al. 2015, figure 12): a gently rolling
-- plain, and craters applied one after the other with
-- outcrop.elevation.replace, oldest first, so that each younger crater
-- cuts the ones before it. A crater is the contour primitive
-- (outcrop.elevation.lake) with a crater's profile: a flat floor, a bowl
-- rising to a raised rim at the shore and an ejecta blanket falling back
-- to the plain over the falloff, where the crater's weight goes to 0 and
-- the replacement blends the blanket into what was there before.
--
--   outcrop run examples/elev_craters.lua [--set size=640] [--out DIR]

local oc = require "outcrop"
local E = oc.elevation

local w = oc.param("size", 640)
local h = w * 9 // 16

-- A small LCG: the same craters on every run and platform.
local state = 1969
local function rand(lo, hi)
  state = (state * 1103515245 + 12345) % 2147483648
  return lo + (hi - lo) * state / 2147483648
end

-- 2 x 2 km around the origin; the plain's terrain reaches 0.4542 x 3200
-- = 1453 m, past the corners (1414 m).
local plain = E.disc{center = {0, 0}, radius = 3200, height = 0,
                     noise = {amplitude = 14, wavelength = 700, octaves = 4,
                              gain = 0.45, seed = 12}}

-- Radii from a power law (many small craters, few large ones), shapes
-- after fresh lunar craters: depth about 0.4 r below the level of the
-- ground where the crater struck, a rim 0.08 r above it, the ejecta
-- blanket out to 0.9 r beyond the rim. Slightly irregular shores (six
-- radii within 6 % of r).
local N = 45
local scene, craters = plain, {}
for i = 1, N do
  local r = 30 * (1 - rand(0, 0.97)) ^ -0.55 -- 30 m to about 200 m
  r = math.min(r, 230)
  local cx, cy = rand(-950, 950), rand(-950, 950)
  local level = (scene:eval(cx, cy)) -- the ground as it is at impact time
  local radii = {}
  for k = 1, 6 do radii[k] = r * (1 + rand(-0.06, 0.06)) end
  local d, rim, out = 0.4 * r, 0.08 * r, 0.9 * r
  local crater = E.lake{center = {cx, cy}, radius = radii, level = level, falloff = out,
                        profile = {{-0.55 * r, -d}, {-0.35 * r, -0.8 * d}, {0, rim},
                                   {0.3 * out, 0.35 * rim}, {out, 0}}}
  scene = E.replace(scene, crater)
  craters[i] = {cx, cy, r, level}
end

-- A fine texture over everything, craters included (a disc of zero
-- height whose weight is about 1 over the square): without it the
-- deepest crater's floor is flat at exactly the tree's lowest bound,
-- where both tracers miss it (see the README).
local texture = E.disc{center = {0, 0}, radius = 8000, height = 0,
                       noise = {amplitude = 2.5, wavelength = 90, octaves = 3,
                                gain = 0.5, seed = 13}}
scene = E.add(scene, texture)

local st = scene:stats()
print(("elev_craters: %d craters, %d nodes, %d primitives, %d bytes; Lipschitz bound %.1f")
      :format(N, st.nodes, st.primitives, st.bytes, scene:lipschitz()))

-- Order = time: where a younger crater overlaps an older one, the floor
-- of the younger is what is left. Print the first such pair.
for j = 2, N do
  local b = craters[j]
  for i = 1, j - 1 do
    local a = craters[i]
    local dist = math.sqrt((a[1] - b[1]) ^ 2 + (a[2] - b[2]) ^ 2)
    if dist < a[3] + 0.5 * b[3] and dist > 0.6 * b[3] then
      local ft, at = texture:eval(b[1], b[2])
      local f = scene:eval(b[1], b[2]) - math.min(1, math.max(0, at)) * ft -- the floor under the texture
      print(("elev_craters: crater %d (r %.0f m) cuts the rim of older crater %d "
             .. "(r %.0f m): floor %.1f m = its own level %.1f m - %.1f m")
            :format(j, b[3], i, a[3], f, b[4], 0.4 * b[3]))
      goto done
    end
  end
end
::done::

-- Grey regolith, darker on the shaded steep walls by the lighting alone;
-- a little lighter on crater rims and ejecta (fresher material).
local function colour(x, y, z, nx, ny, nz)
  local g = 0.16 + 0.03 * math.min(1, math.max(0, (0.95 - nz) / 0.2))
  return g, g, g * 0.97
end

local t = os.clock()
local img = oc.render(scene, {
  size = {w, h},
  camera = {eye = {-1200, -1500, 750}, target = {0, 0, 0}, fov = 40},
  sun = {direction = {-0.8, 0.3, 0.35}, intensity = 2.6},
  sky = {0.02, 0.02, 0.03},
  color = colour,
})
assert(img:write("elev_craters.png"))
print(("elev_craters: wrote elev_craters.png (%.1f s of CPU)"):format(os.clock() - t))
