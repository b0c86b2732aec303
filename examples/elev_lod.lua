-- elev_lod.lua — level of detail along a strip, as Génevaux et al. 2015,
-- figure 16: a long terrain (24 km of ridged mountains along a valley)
-- seen from one end, rendered twice: at full detail, and with
-- outcrop.render(e, {lod = true}), where each disc keeps an octave of
-- its noise only while its wavelength exceeds the pixel's footprint
-- (the octave fading out over a factor of two), so the far mountains
-- cost a few octaves instead of ten. Prints the tree calls and the CPU
-- time of both renders, and writes the LoD picture.
--
--   outcrop run examples/elev_lod.lua [--set size=320] [--set exact=true]
--                                     [--out DIR]
--
-- Both renders step on the tree's first-order models (under the view,
-- the LoD ones: each octave's model times its filter's, the octaves
-- filtered out on a step's whole disc never evaluated).
-- exact=false skips the full-detail render.

local oc = require "outcrop"
local E = oc.elevation

local w = oc.param("size", 320)
local exact = oc.param("exact", true)
local h = w * 9 // 16

-- The strip: x from 0 to 24 km, y from -3 to 3 km. One base disc
-- covering it (its terrain reaches 0.4542 x 30 km = 13.6 km from the
-- strip's middle) and mountains on both sides of the valley, every disc
-- with ten octaves of noise (wavelengths down to 1/512 of the first).
local parts = {E.disc{center = {12000, 0}, radius = 30000, height = 100,
  noise = {amplitude = 60, wavelength = 2000, octaves = 10, gain = 0.5, seed = 160}}}
local state = 16
local function rand(lo, hi)
  state = (state * 1103515245 + 12345) % 2147483648
  return lo + (hi - lo) * state / 2147483648
end
for i = 0, 15 do
  for side = -1, 1, 2 do
    local x = 1500 * i + rand(-400, 400)
    local y = side * rand(1300, 2200)
    local r = rand(1400, 2200)
    parts[#parts + 1] = E.disc{center = {x, y}, radius = r, height = rand(1400, 2400),
      noise = {amplitude = 400, wavelength = 0.6 * r, octaves = 10,
               gain = 0.5, seed = 200 + 2 * i + (side + 1) // 2}}
  end
end
local scene = E.blend(parts)
local st = scene:stats()
print(("elev_lod: %d nodes, %d primitives, %d bytes"):format(st.nodes, st.primitives, st.bytes))

local function colour(x, y, z, nx, ny, nz)
  local rock = math.min(1, math.max(0, (0.85 - nz) / 0.15))
  local snow = math.min(1, math.max(0, (z - 1000) / 150)) * (nz > 0.6 and 1 or 0)
  local r = 0.10 + 0.14 * rock
  local g = 0.15 + 0.06 * rock
  local b = 0.06 + 0.12 * rock
  return r + (0.8 - r) * snow, g + (0.8 - g) * snow, b + (0.82 - b) * snow
end

local opts = {size = {w, h}, camera = {eye = {-3000, 0, 1800}, target = {10000, 0, 0},
                                        fov = 45}, color = colour}
local function run(lod)
  opts.lod = lod
  local t = os.clock()
  local img, s = oc.render(scene, opts)
  return img, s, os.clock() - t
end
local img, s, secs = run(true)
assert(img:write("elev_lod.png"))
print(("elev_lod: with LoD: %.1f tree calls per pixel, %.1f s of CPU (wrote elev_lod.png)")
      :format(s.calls_per_pixel, secs))
if exact then
  local _, s0, secs0 = run(false)
  print(("elev_lod: full detail: %.1f tree calls per pixel, %.1f s of CPU; LoD %.2fx faster")
        :format(s0.calls_per_pixel, secs0, secs0 / secs))
end
