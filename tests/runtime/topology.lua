-- topology.lua — the topology of an example's mesh, run by the
-- interpreter from tests/runtime/examples.sh:
--
--   outcrop run tests/runtime/topology.lua EXAMPLE.lua MIN_GENUS [--set ...]
--
-- Runs EXAMPLE.lua with dofile (it returns {mesh = ...}; the --set
-- parameters reach it through outcrop.param), splits the mesh into
-- connected components (triangles sharing a vertex: the mesher never
-- duplicates one), drops specks of fewer than SPECK vertices, and checks
-- that one component is left, closed and manifold (every edge in exactly
-- two triangles), with Euler characteristic V - E + F = 2 - 2g, g >=
-- MIN_GENUS. Prints the figures; raises on failure.

local example, min_genus = ...
min_genus = assert(tonumber(min_genus), "usage: topology.lua EXAMPLE MIN_GENUS")
local SPECK = 50

local r = dofile(example)
local mesh = assert(r and r.mesh, example .. " returned no mesh")
local nv, nt = mesh:counts()

-- union-find over the vertices, joined along the triangles
local parent = {}
for i = 1, nv do parent[i] = i end
local function find(i)
  while parent[i] ~= i do
    parent[i] = parent[parent[i]]
    i = parent[i]
  end
  return i
end
local function join(a, b)
  a, b = find(a), find(b)
  if a ~= b then parent[b] = a end
end

-- edges counted once each, with the number of triangles using them
local uses, first = {}, {}
local function edge(a, b)
  if a > b then a, b = b, a end
  local k = a * (nv + 1) + b
  uses[k] = (uses[k] or 0) + 1
end
for t = 1, nt do
  local a, b, c = mesh:triangle(t)
  first[t] = a
  join(a, b)
  join(a, c)
  edge(a, b)
  edge(b, c)
  edge(c, a)
end

local V, E, F = {}, {}, {}
for i = 1, nv do
  local k = find(i)
  V[k] = (V[k] or 0) + 1
end
for t = 1, nt do
  local k = find(first[t])
  F[k] = (F[k] or 0) + 1
end
local bad = 0
for k, n in pairs(uses) do
  if n ~= 2 then bad = bad + 1 end
  local root = find(k // (nv + 1))
  E[root] = (E[root] or 0) + 1
end
assert(bad == 0, string.format("%d edges not shared by exactly two triangles", bad))

local kept, specks = {}, 0
for k, v in pairs(V) do
  if v >= SPECK then kept[#kept + 1] = k else specks = specks + 1 end
end
table.sort(kept)
for _, k in ipairs(kept) do
  local chi = V[k] - E[k] + (F[k] or 0)
  print(string.format("topology: component of %d vertices, %d edges, %d triangles: " ..
                      "Euler characteristic %d, genus %g", V[k], E[k], F[k] or 0, chi,
                      (2 - chi) / 2))
end
print(string.format("topology: %d component(s) of %d vertices or more, %d speck(s) dropped",
                    #kept, SPECK, specks))
assert(#kept == 1, string.format("%d components, not one", #kept))
local k = kept[1]
local genus = (2 - (V[k] - E[k] + F[k])) / 2
assert(genus >= min_genus, string.format("genus %g < %d: no through-hole", genus, min_genus))

-- the engine's own count agrees with the one above
local comps = mesh:components()
local big = 0
for _, n in ipairs(comps) do
  if n >= SPECK then big = big + 1 end
end
assert(big == 1 and #comps == #kept + specks,
       string.format("mesh:components() gives %d components (%d big), the count above %d",
                     #comps, big, #kept + specks))
