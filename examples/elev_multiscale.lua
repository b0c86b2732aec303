-- elev_multiscale.lua — a 200 km multi-scale scene with an image
-- primitive, as Génevaux et al. 2015, figure 19 (Table 1: 200 x 200 km,
-- 15 primitives, 3 operators): a heightfield (an fBm grid generated
-- here) mapped by outcrop.elevation.image on a quadrangle 120 km across
-- and replaced into a covering base; twelve mountain discs with ridged
-- noise blended over it; and a main-stem river 180 km long replaced in,
-- its bank level falling from 420 m to 15 m towards the sea in the
-- south-east. Three scales: the base's and the mountains' noise (down
-- to a few hundred metres), the grid's hills (tens of kilometres), the
-- river's valley across the whole scene.
--
--   outcrop run examples/elev_multiscale.lua [--set size=640] [--out DIR]

local oc = require "outcrop"
local E = oc.elevation

local w = oc.param("size", 640)
local h = w * 9 // 16

-- 200 x 200 km around the origin: the base's terrain reaches
-- 0.4542 x 320 km = 145 km, past the corners (141 km).
local base = E.disc{center = {0, 0}, radius = 320000, height = 150,
                    noise = {amplitude = 120, wavelength = 30000, octaves = 6,
                             gain = 0.5, seed = 19}}

-- The image: a 257 x 257 fBm grid (its own units: a cell of 1, a
-- wavelength of 48 cells) on a convex quadrangle, counter-clockwise; the
-- grid's corners (0, 0), (1, 0), (1, 1), (0, 1) go to the quad's
-- corners in order, so a cell is about 470 m. f = 120 + 1400 h, its
-- weight 1 inside but for a 10 km fade along the border.
local grid = oc.heightfield.fbm{size = {257, 257}, cell = 1, wavelength = 48,
                                amplitude = 1, octaves = 5, seed = 20}
local image = E.image{heightfield = grid, height = 1400, offset = 120, falloff = 10000,
                      quad = {{-75000, -55000}, {45000, -70000}, {60000, 50000},
                              {-60000, 65000}}}
local land = E.replace(base, image)

-- Mountains: {x, y, radius, height} (a blend averages them with the
-- land under them, so the peaks come to about half their height plus
-- the land's).
local state = 1919
local function rand(lo, hi)
  state = (state * 1103515245 + 12345) % 2147483648
  return lo + (hi - lo) * state / 2147483648
end
local parts = {land}
for i = 1, 12 do
  local a = 2 * math.pi * (i - 1) / 12 + rand(-0.2, 0.2)
  local d = rand(30000, 80000)
  local r = rand(15000, 30000)
  parts[#parts + 1] = E.disc{center = {d * math.cos(a) - 20000, d * math.sin(a) + 20000},
    radius = r, height = rand(4000, 7000),
    noise = {kind = "ridged", amplitude = 2500, wavelength = 0.4 * r, octaves = 6,
             gain = 0.5, seed = 30 + i}}
end
local relief = E.blend(parts)

-- The main stem, north-west to south-east, widened for the scale of the
-- picture (a cell of the 640-pixel picture is about 300 m): a 900 m
-- channel 25 m deep in a valley 5 km wide either side.
local river = E.river{kind = "main", width = 900, depth = 25, bank = 5000, points = {
  {-140000, 120000, 420}, {-90000, 80000, 330}, {-50000, 70000, 260},
  {-15000, 30000, 190}, {10000, -5000, 130}, {45000, -30000, 80},
  {80000, -70000, 40}, {140000, -110000, 15}}}
local scene = E.replace(relief, river)

local st = scene:stats()
print(("elev_multiscale: %d nodes, %d primitives, %d bytes; Lipschitz bound %.2f")
      :format(st.nodes, st.primitives, st.bytes, scene:lipschitz()))
local _, _, lo, _, _, hi = scene:bounds()
print(("elev_multiscale: elevations within [%.0f, %.0f] m; on the river at (10, -5) km: %.1f m")
      :format(lo, hi, scene:eval(10000, -5000)))

local function colour(x, y, z, nx, ny, nz)
  local _, a = river:eval(x, y)
  if a >= 0.999 then return 0.03, 0.07, 0.10 end
  local rock = math.min(1, math.max(0, (0.8 - nz) / 0.15))
  local snow = math.min(1, math.max(0, (z - 3600) / 400)) * (nz > 0.55 and 1 or 0)
  local r, g, b = 0.09 + 0.15 * rock, 0.15 + 0.05 * rock, 0.05 + 0.12 * rock
  return r + (0.8 - r) * snow, g + (0.8 - g) * snow, b + (0.82 - b) * snow
end

-- The default (segment) tracer. Against tracer = "sphere" at 640 x 360
-- the hit masks differ on 28 of about 149 300 hits, all on the outline of
-- the terrain's edge, and the depths on 61 pixels where a ray grazes a
-- crest: each a sliver shorter than the pixel tolerance at its depth
-- (150-220 m here), which one tracer samples and the other steps over,
-- in both directions; the segment tracer takes 20 height calls per pixel
-- where sphere tracing takes 114.
local t = os.clock()
local img = oc.render(scene, {
  size = {w, h},
  camera = {eye = {-40000, -170000, 120000}, target = {0, -5000, 0}, fov = 50},
  sun = {direction = {-0.75, 0.45, 0.3}, intensity = 2.6},
  color = colour,
})
assert(img:write("elev_multiscale.png"))
print(("elev_multiscale: wrote elev_multiscale.png (%.1f s of CPU)"):format(os.clock() - t))
