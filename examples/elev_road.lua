-- elev_road.lua — a winding road levelling a hillside, as Génevaux et al.
-- 2015, figure 22: a hill of blended discs over a covering base, and a
-- road (outcrop.elevation.road) along a Catmull-Rom path that climbs it
-- in hairpins, replaced in: outcrop.elevation.replace(hill, road) cuts
-- the road's bench into the slope and fills below it, its carriageway
-- level across (a 1 % crown) with 12 m embankments blending back into
-- the hillside. The road's elevations follow the hill along the path,
-- smoothed and held to a gentle grade (at most 7 %).
--
--   outcrop run examples/elev_road.lua [--set size=640] [--out DIR]

local oc = require "outcrop"
local E = oc.elevation

local w = oc.param("size", 640)
local h = w * 9 // 16
local grade = 0.07

-- 0.6 x 0.6 km. The base's terrain reaches 0.4542 x 1000 = 454 m, past
-- the square's corners (424 m).
local base = E.disc{center = {0, 0}, radius = 1000, height = 10,
                    noise = {amplitude = 6, wavelength = 200, octaves = 3, seed = 41}}
local hill = E.blend{base,
  E.disc{center = {20, 40}, radius = 380, height = 120,
         noise = {amplitude = 14, wavelength = 150, octaves = 3, gain = 0.4, seed = 42}},
  E.disc{center = {110, 120}, radius = 230, height = 150,
         noise = {amplitude = 12, wavelength = 110, octaves = 3, gain = 0.4, seed = 43}},
  E.disc{center = {-120, -30}, radius = 240, height = 95,
         noise = {amplitude = 10, wavelength = 120, octaves = 3, gain = 0.4, seed = 44}}}

-- The path up the south-west flank, in hairpins; z from the hill, then
-- smoothed and held to the grade (from the bottom up, then down again).
local path = {{-300, -240}, {-150, -215}, {-10, -170}, {70, -110}, {30, -55},
              {-80, -40}, {-130, 20}, {-70, 80}, {40, 70}, {120, 40}, {180, 90},
              {160, 170}, {80, 210}}
local pts = {}
for i, p in ipairs(path) do pts[i] = {p[1], p[2], (hill:eval(p[1], p[2]))} end
for _ = 1, 2 do -- smooth the profile along the path
  local z = {}
  for i = 1, #pts do
    local a, b = pts[math.max(1, i - 1)][3], pts[math.min(#pts, i + 1)][3]
    z[i] = 0.25 * a + 0.5 * pts[i][3] + 0.25 * b
  end
  for i = 1, #pts do pts[i][3] = z[i] end
end
local function dist(a, b) return math.sqrt((a[1] - b[1]) ^ 2 + (a[2] - b[2]) ^ 2) end
for i = 2, #pts do
  local d = grade * dist(pts[i], pts[i - 1])
  pts[i][3] = math.max(pts[i - 1][3] - d, math.min(pts[i - 1][3] + d, pts[i][3]))
end
for i = #pts - 1, 1, -1 do
  local d = grade * dist(pts[i], pts[i + 1])
  pts[i][3] = math.max(pts[i + 1][3] - d, math.min(pts[i + 1][3] + d, pts[i][3]))
end

local road = E.road{points = pts, width = 8, shoulder = 1.5, embankment = 12}
local scene = E.replace(hill, road)

local st = scene:stats()
print(("elev_road: %d nodes, %d primitives, %d bytes; Lipschitz bound %.1f")
      :format(st.nodes, st.primitives, st.bytes, scene:lipschitz()))
print(("elev_road: the road climbs from %.1f m to %.1f m"):format(pts[1][3], pts[#pts][3]))

-- Albedos (linear): asphalt on the carriageway and shoulders (the road's
-- weight is 1 there), grass, rock where steeper (cuttings, fills).
local function colour(x, y, z, nx, ny, nz)
  local _, a = road:eval(x, y)
  if a >= 0.999 then return 0.07, 0.07, 0.075 end
  local rock = math.min(1, math.max(0, (0.88 - nz) / 0.1))
  return 0.10 + 0.12 * rock, 0.17 + 0.01 * rock, 0.05 + 0.10 * rock
end

local t = os.clock()
local img = oc.render(scene, {
  size = {w, h},
  camera = {eye = {-520, -560, 330}, target = {-20, 0, 60}, fov = 40},
  color = colour,
})
assert(img:write("elev_road.png"))
print(("elev_road: wrote elev_road.png (%.1f s of CPU)"):format(os.clock() - t))
