-- layers_arches.lua — arches carved into a cliff block with the material
-- stack tools (Peytavie et al. 2009, figure 23): a block of bedrock, a
-- rough cliff profile swept along its front (a ledge and an overhang),
-- two bays swept into the face and a corridor behind leaving a fin
-- between them, an arch swept through the fin and another through the
-- ledge, a few carving
-- strokes to break the walls, and the walls' surface eroded into sand and
-- rocks that settle at the foot. Rendered and meshed textured by the
-- visible material ratio (section 6) with the surface's sigma.
--
--   outcrop run examples/layers_arches.lua [--set cell=0.5] [--out DIR]

local oc = require "outcrop"

local cell = oc.param("cell", 0.5)
local nx, ny = math.floor(60 / cell) + 1, math.floor(40 / cell) + 1

local s = oc.layers.new{size = {nx, ny}, cell = cell, layers = {{"bedrock", 28}}}
local t0 = os.clock()

-- the cliff: everything in front of a wavy line at y ~ 16 removed above
-- the ground (z = 4), with a ledge at 10 m and an overhang near the top;
-- u runs to the right of travel (+x), i.e. towards -y
local front = {{-0.5, 40}, {40, 40}, {40, 4}, {9, 4}, {9, 10}, {4, 10},
               {3.5, 16}, {1, 20}, {-1.5, 26}, {-0.5, 30}}
local removed = -s:sweep{path = {{-8, 17, 0}, {14, 15, 0}, {30, 18, 0},
                                 {46, 15, 0}, {68, 17, 0}},
                         profiles = front, mode = "tunnel", stabilize = false}

-- two bays cut into the face (open to the sky, 10 m wide) and a corridor
-- joining them behind: the rock between them stands free, a fin
local bay = {{-5, 40}, {5, 40}, {5, 4.5}, {3, 4}, {-3, 4}, {-5, 4.5}}
for _, x in ipairs{18, 42} do
  removed = removed - s:sweep{path = {{x, 8, 0}, {x, 30, 0}}, profiles = bay,
                              mode = "tunnel", stabilize = false}
end
local corridor = {{-3, 40}, {3, 40}, {3, 4.5}, {2, 4}, {-2, 4}, {-3, 4.5}}
removed = removed - s:sweep{path = {{18, 27, 0}, {42, 27, 0}},
                            profiles = corridor, mode = "tunnel",
                            stabilize = false}

-- the arches: one through the fin, a smaller one through the ledge
local arch = {}
for k = 0, 15 do
  local a = 2 * math.pi * k / 16
  arch[#arch + 1] = {3.5 * math.cos(a), 5.5 * math.sin(a)}
end
removed = removed - s:sweep{path = {{30, 10, 11}, {30, 30, 11}},
                            profiles = arch, mode = "tunnel", stabilize = false}
local small = {}
for k, p in ipairs(arch) do small[k] = {0.6 * p[1], 0.45 * p[2]} end
removed = removed - s:sweep{path = {{8, 4, 6.5}, {8, 14, 6.5}},
                            profiles = small, mode = "tunnel", stabilize = false}

-- carving strokes on the walls
for _, c in ipairs{{8, 17, 20}, {52, 16, 14}, {50, 24, 24}, {4, 22, 25}} do
  local dv = s:sculpt{center = c, radius = 3, mode = "carve", stabilize = false}
  removed = removed - dv
end

-- weathering: the walls' surface turned into sand and rocks that settle
local eroded, res = s:erode{region = {0, 8, 60, 26}, ratio = 0.4, depth = 0.3,
                            mode = "surface", stabilize = {tolerance = 0.01}}
print(string.format("layers_arches: %.0f m^3 carved, %.0f m^3 eroded and " ..
                    "settled in %d passes (%.1f s CPU)", removed, eroded,
                    res.iterations, os.clock() - t0))
local st = s:stats()
print(string.format("layers_arches: %d stacks, %d layers, %d bytes",
                    st.stacks, st.layers, st.bytes))

local solid = s:field{sigma = 1.5 * cell}
local colors = s:colors{sigma = 1.5 * cell, bedrock = {0.36, 0.22, 0.14}}
local box = {0, 0, 0.5, 60, 40, 30}
local mesh = oc.polygonize(solid, {box = box, cell = cell})
mesh:write("layers_arches.ply", {colors = colors})
print(string.format("layers_arches: %d triangles", mesh:stats().triangles))
oc.render(solid, {camera = {eye = {50, -26, 26}, target = {28, 18, 10},
                            fov = 48},
                  size = {800, 450}, color = colors}):write("layers_arches.png")
print("layers_arches: wrote layers_arches.ply, layers_arches.png")
