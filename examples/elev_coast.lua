-- elev_coast.lua — a coast built from feature primitives (Génevaux et
-- al. 2015) and amplified in 3D by the sea-erosion generator (Paris et
-- al. 2019, §6.1): an elevation tree gives a plateau 25 m high ending in
-- a cliff over a sea floor at -12 m, and a headland (a neck 12 m wide
-- out to a round head 28 m across, 14 m high). outcrop.terrain(e) makes
-- it a 3D terrain, outcrop.generate.sea erodes a band around sea level
-- in bedded rock with a soft pocket under the neck and a hard head: the
-- two hollows meet under the neck and leave an arch over the sea.
--
--   outcrop run examples/elev_coast.lua [--set cell=1] [--set size=640]
--        [--set render=false] [--set trace=grid|tree] [--out DIR]
--
-- Writes elev_coast.ply (the mesh of the eroded tree, coloured by
-- resistance) and, unless render=false, elev_coast.png (480 x 270, from
-- the sea west of the neck, looking through the arch). Run by dofile, it
-- returns {mesh =, scene =, tree =}.
--
-- The picture: the 3D tracer is today 15 to 30 times slower on
-- oc.terrain(tree) than on oc.terrain of the tree's grid (more steps, and
-- each one traverses the tree), so by default (trace=grid) the picture
-- traces the same erosion run over oc.terrain(ground), the tree sampled
-- at 1 m, which the generator reads anyway; trace=tree traces the
-- eroded tree itself (several minutes).

local oc = require "outcrop"
local E, G = oc.elevation, oc.geology

local cell = oc.param("cell", 1)
local w = oc.param("size", 480)
local picture = oc.param("render", true)
local trace = oc.param("trace", "grid")
assert(trace == "grid" or trace == "tree", "trace must be 'grid' or 'tree'")
local h = w * 9 // 16

-- The tree, over a 300 x 200 m box from the origin. The sea floor is a
-- covering disc at -12 m (its terrain reaches 0.4542 x 600 = 272 m from
-- the centre, past the box's corners at 180 m).
local floor = E.disc{center = {150, 100}, radius = 600, height = -12}

-- A curve's weight is 1 over its core and falls to 0 over the next
-- R - core metres, so replacing a level curve into the floor gives a
-- steep step there: f = (1 - alpha) f_floor + alpha f_curve. The plateau
-- is a wide curve (core 60 m) along a wavy line 60 m north of the cliff
-- (its curvature radius, at least 135 m, stays above R = 66 m): the cliff
-- at y = 90 + 5 sin(x / 26) falls 37 m over 6 m.
local ridge = {}
for i = 0, 20 do
  local x = -50 + 20 * i
  ridge[#ridge + 1] = {x, 150 + 5 * math.sin(x / 26), 25}
end
local flat = {{-100, 0}, {100, 0}}
local plateau = E.curve{points = ridge, radius = 66, core = 60, profile = flat}

-- The headland, lower than the plateau: a neck (core 6 m, so 12 m wide,
-- from inside the cliff out to y = 62) and a head, a short segment whose
-- rounded core (13 m) makes a round tip at y = 42.
local neck = E.curve{points = {{150, 100, 14}, {150, 62, 14}}, spline = "linear",
                     radius = 9, core = 6, profile = flat}
local head = E.curve{points = {{150, 58, 14}, {150, 56, 14}}, spline = "linear",
                     radius = 17, core = 13, profile = flat}

-- A ground texture added over everything (a disc of zero height whose
-- weight is close to 1 over the box): a few metres of relief.
local relief = E.disc{center = {150, 100}, radius = 1500, height = 0,
                      noise = {amplitude = 3, wavelength = 60, octaves = 3, seed = 4}}
local tree = E.add(E.replace(E.replace(E.replace(floor, plateau), neck), head), relief)

local st = tree:stats()
print(("elev_coast: tree of %d nodes, %d primitives, %d bytes; cliff top %.1f m, "
       .. "neck %.1f m, head %.1f m, sea floor %.1f m")
      :format(st.nodes, st.primitives, st.bytes, tree:eval(60, 150), tree:eval(150, 75),
              tree:eval(150, 57), tree:eval(60, 20)))

-- Into 3D: the tree as a terrain over the box, and sampled as the grid
-- the generator takes its footprint, slopes and sea level from.
local box2 = {0, 0, 300, 200}
local terrain = oc.terrain(tree, {domain = box2})
local ground = oc.heightfield.from(tree, {origin = {0, 0}, size = {301, 201}, cell = 1})

-- The rock (as examples/sea_cliffs.lua): beds of resistance 0.6 to 1.2,
-- a soft pocket in the neck where the sea breaks through and a hard head
-- that keeps its foot.
local rock = G.strata{wavelength = 6, octaves = 3, amplitude = 0.6, offset = 0.6, seed = 2}
  + G.sphere{center = {150, 78, 1}, radius = 7, falloff = 5, resistance = -0.9}
  + G.sphere{center = {150, 56, 0}, radius = 10, falloff = 4, resistance = 1.5}

local function erode(t)
  local n, info = oc.generate.sea{heightfield = ground, terrain = t, geology = rock,
                                  sea_level = 0, range = 12, radius = 6, spacing = 1.5,
                                  strength = 0.8, beta = 0.05, steps = 8}
  print(("elev_coast: sea erosion: %d columns, %d samples, %d primitives")
        :format(info.columns, info.samples, info.primitives))
  return n
end
local scene = erode(terrain)

local shade = G.clamp(rock)
local palette = {{0.6, {0.30, 0.20, 0.13}}, {0.85, {0.55, 0.42, 0.30}},
                 {1.0, {0.78, 0.70, 0.58}}}
local mesh = oc.polygonize(scene, {box = {0, 0, -14, 300, 200, 40}, cell = cell,
                                   colors = {field = shade, palette = palette},
                                   min_component = 50})
assert(mesh:write("elev_coast.ply"))
local ms = mesh:stats()
print(("elev_coast: wrote elev_coast.ply (%d triangles, %.2f s)")
      :format(ms.triangles, ms.seconds))
local result = {mesh = mesh, scene = scene, tree = tree}
if not picture then return result end

-- For the picture only: the sea as a slab 1.5 m under sea level, blue
-- through a colour field that adds 4 in the water (as sea_cliffs.lua).
local water = oc.box{min = {-10, -10, -20}, max = {310, 210, -1.5}, falloff = 0.5}
local wet = oc.box{min = {-10, -10, -20}, max = {310, 210, -0.5}, falloff = 0.1,
                   energy = 4}
local rpal = {{0.6, {0.30, 0.20, 0.13}}, {0.85, {0.55, 0.42, 0.30}},
              {1.0, {0.78, 0.70, 0.58}}, {1.5, {0.78, 0.70, 0.58}},
              {1.9, {0.10, 0.25, 0.35}}, {6.0, {0.10, 0.25, 0.35}}}
local shown = trace == "tree" and scene or erode(oc.terrain(ground))
local t = os.clock()
oc.render(oc.union{shown, water},
          {camera = {eye = {88, 66, 6}, target = {150, 80, 4}, fov = 38},
           sun = {direction = {-0.6, -0.5, 0.55}, intensity = 1.4}, ao = false,
           size = {w, h}, color = shade + wet, palette = rpal}):write("elev_coast.png")
print(("elev_coast: wrote elev_coast.png (%.1f s of CPU)"):format(os.clock() - t))
return result
