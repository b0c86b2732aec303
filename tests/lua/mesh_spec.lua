-- mesh_spec.lua — outcrop.polygonize and the mesh userdata: surfaces where
-- the field equals T, the options, every error, the written files (read
-- back and parsed here), colours, and lifetimes under an eager collector.
local oc = require "outcrop"
local Fs = require "helpers.files"
local read_file = Fs.read_file
local listdir = Fs.listdir
local R = require "helpers.ref"
require "helpers.gcstress" -- OUTCROP_GC_STRESS: eager collector

local F = "mesh_spec.lua"
local function check(f, fname, ...) return R.check_error(f, F, fname, ...) end
local reg = debug.getregistry()

local C = {0.25, -0.5, 1}
local RADIUS = 2
local ball = oc.point{center = C, radius = RADIUS}
-- g(r / R) = T  =>  r = R sqrt(1 - T^(1/3))
local function iso_radius(T) return RADIUS * math.sqrt(1 - T ^ (1 / 3)) end

-- Mesh colours are linear; PLY bytes are their sRGB encoding (IEC
-- 61966-2-1), 255 * s unrounded here.
local function srgb255(x)
  x = math.max(0, math.min(1, x))
  return 255 * (x <= 0.0031308 and 12.92 * x or 1.055 * x ^ (1 / 2.4) - 0.055)
end



local function vertices(m)
  local nv = m:counts()
  local i = 0
  return function()
    i = i + 1
    if i <= nv then return i, {m:vertex(i)} end
  end
end

-- The largest |f - T| over the vertices, and the largest distance error
-- to the analytic sphere of the ball at T.
local function surface_error(m, node, T)
  local ferr, derr = 0, 0
  for _, v in vertices(m) do
    ferr = math.max(ferr, math.abs(node:eval(v[1], v[2], v[3]) - T))
    derr = math.max(derr, math.abs(R.dist_point(v, C) - iso_radius(T)))
  end
  return ferr, derr
end

-- A binary little-endian PLY reader, independent of the writer: header,
-- then the vertex records as the header declares them, then the faces.
local ply_types = {float = "f", uchar = "B", uint = "I4", int = "i4"}
local function read_ply(data)
  local head_end = assert(data:find("end_header\n", 1, true), "no end_header")
  local header = data:sub(1, head_end + #"end_header\n" - 1)
  local pos = #header + 1
  local ply = {header = header, props = {}, verts = {}, faces = {}}
  assert(header:sub(1, 4) == "ply\n", "no ply magic")
  assert(header:find("format binary_little_endian 1.0\n", 1, true))
  local elem
  for line in header:gmatch("[^\n]+") do
    local name, n = line:match("^element (%S+) (%d+)$")
    if name then elem = name; ply["n" .. name] = tonumber(n) end
    local ty, pname = line:match("^property (%S+) (%S+)$")
    if ty and elem == "vertex" then
      ply.props[#ply.props + 1] = pname
      ply.fmt = (ply.fmt or "<") .. assert(ply_types[ty], ty)
    end
  end
  for i = 1, ply.nvertex do
    local rec = {string.unpack(ply.fmt, data, pos)}
    pos = table.remove(rec)
    local v = {}
    for k, name in ipairs(ply.props) do v[name] = rec[k] end
    ply.verts[i] = v
  end
  for i = 1, ply.nface do
    local n
    n, pos = string.unpack("<B", data, pos)
    assert(n == 3, "a face that is not a triangle")
    local a, b, c
    a, b, c, pos = string.unpack("<I4I4I4", data, pos)
    ply.faces[i] = {a, b, c}
  end
  assert(pos == #data + 1, "trailing bytes after the faces")
  return ply
end

describe("outcrop.polygonize", function()
  after_each(function() oc.threshold = 0.5 end)

  it("meshes a point sphere on its iso-surface, closed and of genus 0", function()
    local m = oc.polygonize(ball, {cell = 0.1})
    local nv, nt = m:counts()
    assert.is_true(nv > 100 and nt > 100)
    -- closed genus-0 triangle mesh: V - E + F = 2 with E = 3F/2
    assert.are.equal(2 * (nv - 2), nt)
    local ferr, derr = surface_error(m, ball, 0.5)
    assert.is_true(ferr < 1e-5, "field off the threshold by " .. ferr)
    assert.is_true(derr < 1e-5, "vertex off the sphere by " .. derr)
    -- normals: unit, pointing outwards
    for _, v in vertices(m) do
      R.close(R.len({v[4], v[5], v[6]}), 1, 1e-5)
      local out = R.mul(R.sub(v, C), 1 / R.dist_point(v, C))
      assert.is_true(R.dot(out, {v[4], v[5], v[6]}) > 0.99)
    end
  end)

  it("returns triangles as 1-based vertex indices, counter-clockwise from outside #slowgc", function()
    local m = oc.polygonize(ball, {cell = 0.2})
    local nv, nt = m:counts()
    for t = 1, nt do
      local a, b, c = m:triangle(t)
      for _, i in ipairs{a, b, c} do
        assert.is_true(math.type(i) == "integer" and i >= 1 and i <= nv)
      end
      assert.is_true(a ~= b and b ~= c and a ~= c)
      local pa, pb, pc = {m:vertex(a)}, {m:vertex(b)}, {m:vertex(c)}
      local e1, e2 = R.sub(pb, pa), R.sub(pc, pa)
      local n = {e1[2] * e2[3] - e1[3] * e2[2], e1[3] * e2[1] - e1[1] * e2[3],
        e1[1] * e2[2] - e1[2] * e2[1]}
      assert.is_true(R.dot(n, R.sub(pa, C)) > 0, "triangle " .. t .. " faces inwards")
    end
  end)

  it("reports stats consistent with the counts", function()
    local m = oc.polygonize(ball, {cell = 0.25})
    local st = m:stats()
    local nv, nt = m:counts()
    assert.are.equal(nv, st.vertices)
    assert.are.equal(nt, st.triangles)
    assert.are.equal("integer", math.type(st.field_calls))
    assert.are.equal("integer", math.type(st.cells_visited))
    assert.is_true(st.field_calls >= nv)
    assert.is_true(st.cells_visited > 0)
    assert.are.equal("number", type(st.seconds))
    assert.is_true(st.seconds >= 0 and st.seconds < 60)
    local keys = {}
    for k in pairs(st) do keys[#keys + 1] = k end
    table.sort(keys)
    assert.are.same({"cells_visited", "field_calls", "seconds", "triangles", "vertices"}, keys)
  end)

  it("takes a resolution per axis, and defaults to 64 cubic cells along the longest side", function()
    local box = {-2, -3, -1, 2, 2, 3}
    local a = oc.polygonize(ball, {box = box, resolution = {8, 10, 12}, full_grid = true})
    local b = oc.polygonize(ball, {box = box, resolution = {16, 10, 12}, full_grid = true})
    assert.is_true(a:stats().cells_visited >= 8 * 10 * 12)
    assert.is_true(b:stats().cells_visited > a:stats().cells_visited)
    assert.is_true(b:counts() > a:counts())
    local function same(m1, m2)
      assert.are.same({m1:counts()}, {m2:counts()})
      assert.are.equal(m1:stats().cells_visited, m2:stats().cells_visited)
      assert.are.equal(m1:stats().field_calls, m2:stats().field_calls)
      local nv = m1:counts()
      for _, i in ipairs{1, nv // 3, nv} do assert.are.same({m1:vertex(i)}, {m2:vertex(i)}) end
    end
    -- default box: the ball's bounds, a cube of side 2 R
    local d = oc.polygonize(ball, {full_grid = true})
    same(d, oc.polygonize(ball, {full_grid = true, resolution = {64, 64, 64}}))
    same(d, oc.polygonize(ball, {full_grid = true, cell = 2 * RADIUS / 64}))
    same(d, oc.polygonize(ball, {full_grid = true, box = {C[1] - 2, C[2] - 2, C[3] - 2, C[1] + 2, C[2] + 2, C[3] + 2}}))
    -- a box twice as long in x than in y and z: the 64 cells go along x
    local wbox = {-4, -2, -1, 4, 2, 3}
    same(oc.polygonize(ball, {box = wbox}), oc.polygonize(ball, {box = wbox, resolution = {64, 32, 32}}))
  end)

  it("finds fewer field calls with surface bounds than over the full grid", function()
    local scene = ball + oc.point{center = {9, 9, 9}, radius = 1}
    local box = {-2, -3, -1, 10, 10, 10}
    local a = oc.polygonize(scene, {box = box, cell = 0.25})
    local b = oc.polygonize(scene, {box = box, cell = 0.25, full_grid = true})
    assert.are.same({a:counts()}, {b:counts()})
    assert.is_true(a:stats().field_calls < b:stats().field_calls)
  end)

  it("meshes at 'threshold', compiling the node with it", function()
    local m = oc.polygonize(ball, {cell = 0.1, threshold = 0.3})
    local ferr, derr = surface_error(m, ball, 0.3)
    assert.is_true(ferr < 1e-5 and derr < 1e-5, ferr .. " " .. derr)
    -- a difference depends on T: min(fa, 2T - fb)
    local d = ball - oc.point{center = {C[1] + 1.5, C[2], C[3]}, radius = 1.5}
    local md = oc.polygonize(d, {cell = 0.1, threshold = 0.4})
    oc.threshold = 0.4
    local worst = 0
    for _, v in vertices(md) do
      worst = math.max(worst, math.abs(d:eval(v[1], v[2], v[3]) - 0.4))
    end
    assert.is_true(worst < 1e-5, "difference meshed off its surface by " .. worst)
  end)

  it("defaults 'threshold' to outcrop.threshold", function()
    oc.threshold = 0.3
    local m = oc.polygonize(ball, {cell = 0.1})
    local ferr = surface_error(m, ball, 0.3)
    assert.is_true(ferr < 1e-5)
    oc.threshold = 0.5
    local m2 = oc.polygonize(ball, {cell = 0.1})
    assert.is_true(surface_error(m2, ball, 0.5) < 1e-5)
    assert.is_true(m:counts() > m2:counts()) -- the larger sphere
  end)

  it("caps a solid cut by the box unless 'open'", function()
    local box = {-3, -3, -2, 3, 3, C[3]} -- cuts the ball through its centre
    local closed = oc.polygonize(ball, {box = box, cell = 0.1})
    local open = oc.polygonize(ball, {box = box, cell = 0.1, open = true})
    local nvc, ntc = closed:counts()
    local nvo, nto = open:counts()
    assert.are.equal(2 * (nvc - 2), ntc) -- still a closed surface
    assert.is_true(nto < ntc and nvo < nvc)
    for _, v in vertices(closed) do
      assert.is_true(v[3] <= C[3] + 1e-5)
    end
    -- an open hemisphere is a disc: V - E + F = 1, boundary edges counted once
    local edges = {}
    for t = 1, nto do
      local tri = {open:triangle(t)}
      for k = 1, 3 do
        local a, b = tri[k], tri[k % 3 + 1]
        local key = math.min(a, b) .. ":" .. math.max(a, b)
        edges[key] = (edges[key] or 0) + 1
      end
    end
    local ne = 0
    for _ in pairs(edges) do ne = ne + 1 end
    assert.are.equal(1, nvo - ne + nto)
  end)

  it("places vertices more exactly with more root-finding steps", function()
    local few = oc.polygonize(ball, {cell = 0.4, steps = 1})
    local many = oc.polygonize(ball, {cell = 0.4, steps = 20})
    assert.are.same({few:counts()}, {many:counts()})
    local e1 = surface_error(few, ball, 0.5)
    local e20 = surface_error(many, ball, 0.5)
    assert.is_true(e20 < 1e-6, "20 steps left " .. e20)
    assert.is_true(e1 > 10 * e20, "1 step: " .. e1 .. ", 20 steps: " .. e20)
  end)

  it("gives an empty mesh where the box holds no surface", function()
    local m = oc.polygonize(ball, {box = {10, 10, 10, 11, 11, 11}, cell = 0.5})
    assert.are.same({0, 0}, {m:counts()})
    assert.are.equal("outcrop.mesh: 0 vertices, 0 triangles", tostring(m))
    check(function() m:vertex(1) end, "mesh:vertex", "the mesh has no vertices (got 1)")
  end)

  it("needs a box for unbounded nodes", function()
    local plane = oc.plane{origin = {0, 0, 0}, normal = {0, 0, 1}}
    check(function() oc.polygonize(plane) end, "outcrop.polygonize", "the node's bounds are infinite", "'box'")
    local m = oc.polygonize(plane, {box = {-1, -1, -1, 1, 1, 1}, cell = 0.25})
    local _, nt = m:counts()
    assert.is_true(nt > 0)
    for _, v in vertices(m) do
      -- the plane's iso-surface is z = falloff * sqrt(1 - T^(1/3)) or the box caps
      local top = math.sqrt(1 - 0.5 ^ (1 / 3))
      assert.is_true(v[3] <= top + 1e-5)
    end
  end)
end)

describe("outcrop.polygonize checks", function()
  local P = "outcrop.polygonize"
  local turb = oc.turbulence{wavelength = 1}

  it("its arguments", function()
    check(function() oc.polygonize(5) end, P, "argument #1 must be an outcrop node (got 5)")
    check(function() oc.polygonize() end, P, "argument #1 must be an outcrop node (got no value)")
    check(function() oc.polygonize(ball, 5) end, P, "expected a table of named fields (got 5)")
    check(function() oc.polygonize(ball, {}, 3) end, P, "too many arguments")
    check(function() oc.polygonize(ball, {cel = 0.1}) end, P, "unknown field 'cel'", "did you mean 'cell'?")
    check(function() oc.polygonize(ball, {0.1}) end, P, "unexpected array item [1]")
  end)

  it("'box'", function()
    check(function() oc.polygonize(ball, {box = {0, 0, 0, 1, 1}}) end, P, "'box' must be {x0, y0, z0, x1, y1, z1}")
    check(function() oc.polygonize(ball, {box = "all"}) end, P, "'box' must be {x0, y0, z0, x1, y1, z1} (got string)")
    check(function() oc.polygonize(ball, {box = {0, 0, 0, 1, "1", 1}}) end, P, "'box'", "(item 5 is string)")
    check(function() oc.polygonize(ball, {box = {0, 0, 0, 1, 1, math.huge}}) end, P, "'box'", "(item 6 is inf)")
    check(function() oc.polygonize(ball, {box = {0, 0, 0, 1, -1, 1}}) end, P, "needs x0 < x1, y0 < y1 and z0 < z1")
    check(function() oc.polygonize(ball, {box = {0, 0, 1, 1, 1, 1}}) end, P, "needs x0 < x1")
    check(function() oc.polygonize(turb) end, P, "the node's bounds are infinite: give 'box'")
    local nothing = oc.point{center = {0, 0, 0}, radius = 1} & oc.point{center = {5, 0, 0}, radius = 1}
    check(function() oc.polygonize(nothing) end, P, "the node's bounds are empty", "give 'box'")
    assert.are.same({0, 0}, {oc.polygonize(nothing, {box = {-1, -1, -1, 1, 1, 1}}):counts()})
    check(function() oc.polygonize(ball, {box = {-1e308, 0, 0, 1e308, 1, 1}}) end, P, "'box' must be finite")
    check(function() oc.polygonize(oc.plane{origin = {0, 0, 0}, normal = {1, 0, 0}}, {cell = 1}) end, P, "infinite")
  end)

  it("'cell' and 'resolution'", function()
    check(function() oc.polygonize(ball, {cell = -1}) end, P, "'cell' must be a positive number (got -1)")
    check(function() oc.polygonize(ball, {cell = 0}) end, P, "'cell' must be a positive number (got 0)")
    check(function() oc.polygonize(ball, {cell = "1"}) end, P, "'cell'", "(got string)")
    check(function() oc.polygonize(ball, {cell = 0 / 0}) end, P, "'cell'", "positive")
    check(function() oc.polygonize(ball, {cell = 0.1, resolution = {4, 4, 4}}) end, P, "give either 'cell' or 'resolution', not both")
    check(function() oc.polygonize(ball, {resolution = {4, 4}}) end, P, "'resolution' must be {nx, ny, nz}")
    check(function() oc.polygonize(ball, {resolution = 8}) end, P, "'resolution' must be {nx, ny, nz}", "(got 8)")
    check(function() oc.polygonize(ball, {resolution = {4, 0, 4}}) end, P, "'resolution'", "integers in 1..", "(item 2 is 0)")
    check(function() oc.polygonize(ball, {resolution = {4, 4, 4.5}}) end, P, "'resolution'", "(item 3 is 4.5)")
    check(function() oc.polygonize(ball, {resolution = {4, 4, 1e7}}) end, P, "'resolution'", "1..1048576", "(item 3 is 10000000)")
    check(function() oc.polygonize(ball, {cell = 1e-9}) end, P, "'cell'", "cells along x")
    check(function() oc.polygonize(ball, {resolution = {1048576, 1048576, 1048576}}) end, P, "too large")
  end)

  it("'threshold', 'open', 'steps', 'full_grid'", function()
    check(function() oc.polygonize(ball, {threshold = 0}) end, P, "'threshold' must be a positive number (got 0)")
    check(function() oc.polygonize(ball, {threshold = "high"}) end, P, "'threshold'", "(got string)")
    check(function() oc.polygonize(ball, {open = 1}) end, P, "'open' must be a boolean (got 1)")
    check(function() oc.polygonize(ball, {full_grid = "yes"}) end, P, "'full_grid' must be a boolean (got string)")
    check(function() oc.polygonize(ball, {steps = 0}) end, P, "'steps' must be an integer in 1..64 (got 0)")
    check(function() oc.polygonize(ball, {steps = 2.5}) end, P, "'steps'", "integer")
    oc.threshold = -1
    local ok, err = pcall(oc.polygonize, ball)
    oc.threshold = 0.5
    assert.is_false(ok)
    assert.matches("outcrop.threshold must be a positive number", err, 1, true)
  end)

  it("'colors'", function()
    local pal = {{0, {0, 0, 1}}, {1, {1, 0, 0}}}
    check(function() oc.polygonize(ball, {colors = 5}) end, P, "'colors' must be a function or a table {field =, palette =} (got 5)")
    check(function() oc.polygonize(ball, {colors = {palette = pal}}) end, P, "missing field 'colors.field'")
    check(function() oc.polygonize(ball, {colors = {field = 5, palette = pal}}) end, P, "'colors.field' must be an outcrop node (got 5)")
    check(function() oc.polygonize(ball, {colors = {field = ball}}) end, P, "missing field 'colors.palette'")
    check(function() oc.polygonize(ball, {colors = {field = ball, pallete = pal}}) end, P, "unknown field 'colors.pallete'", "did you mean 'colors.palette'?")
    check(function() oc.polygonize(ball, {colors = {field = ball, palette = {}}}) end, P, "'colors.palette' must be an array of 1..65536 {value, {r, g, b}}")
    check(function() oc.polygonize(ball, {colors = {field = ball, palette = {{0, {0, 0, 0}}, 5}}}) end, P, "'colors.palette[2]' must be {value, {r, g, b}} (got 5)")
    check(function() oc.polygonize(ball, {colors = {field = ball, palette = {{"a", {0, 0, 0}}}}}) end, P, "'colors.palette[1]' value must be a finite number (got string)")
    check(function() oc.polygonize(ball, {colors = {field = ball, palette = {{1, {0, 0, 0}}, {0, {1, 1, 1}}}}}) end, P, "'colors.palette' values must be in ascending order", "item 2")
    check(function() oc.polygonize(ball, {colors = {field = ball, palette = {{0, {255, 0, 0}}}}}) end, P, "'colors.palette[1]' colour components must be in [0, 1] (got r = 255)")
    check(function() oc.polygonize(ball, {colors = {field = ball, palette = {{0, {0, 0}}}}}) end, P, "'colors.palette[1]' colour must be {r, g, b}")
  end)
end)

describe("mesh", function()
  local m = oc.polygonize(ball, {cell = 0.5})
  local nv, nt = m:counts()

  it("has a tostring and a type name", function()
    assert.are.equal(string.format("outcrop.mesh: %d vertices, %d triangles", nv, nt), tostring(m))
    -- the metatable is protected: the type name shows in messages only
    assert.are.equal("protected", getmetatable(m))
  end)

  it("vertex and triangle check their index", function()
    check(function() m:vertex(0) end, "mesh:vertex", "the vertex index must be an integer in 1.." .. nv .. " (got 0)")
    check(function() m:vertex(nv + 1) end, "mesh:vertex", "(got " .. nv + 1 .. ")")
    check(function() m:vertex(1.5) end, "mesh:vertex", "integer")
    check(function() m:vertex("1") end, "mesh:vertex", "(got string)")
    check(function() m:vertex(1, 2) end, "mesh:vertex", "too many arguments")
    check(function() m:triangle(0) end, "mesh:triangle", "the triangle index must be an integer in 1.." .. nt)
    check(function() m:triangle(nt + 1) end, "mesh:triangle", "(got " .. nt + 1 .. ")")
    assert.are.equal(6, select("#", m:vertex(nv)))
    assert.are.equal(3, select("#", m:triangle(nt)))
  end)

  it("methods refuse other values", function()
    local ok, err = pcall(m.vertex, 5, 1)
    assert.is_false(ok)
    assert.matches("outcrop.mesh expected, got number", err, 1, true)
    ok, err = pcall(m.counts, ball)
    assert.is_false(ok)
    assert.matches("outcrop.mesh expected, got outcrop.node", err, 1, true)
  end)

  it("can be closed early with <close>", function()
    local saved
    do
      local mm <close> = oc.polygonize(ball, {cell = 0.5})
      saved = mm
      assert.is_true(mm:counts() > 0)
    end
    assert.are.equal("outcrop.mesh: (closed)", tostring(saved))
    check(function() saved:counts() end, "mesh:counts", "the mesh was closed")
    check(function() saved:vertex(1) end, "mesh:vertex", "the mesh was closed")
    check(function() saved:write("/tmp/x.ply") end, "mesh:write", "the mesh was closed")
    do local again <close> = saved end -- twice is harmless
    assert.are.equal("outcrop.mesh: (closed)", tostring(saved))
  end)
end)

describe("mesh:write", function()
  local m = oc.polygonize(ball, {cell = 0.4})
  local nv, nt = m:counts()
  local dir
  before_each(function() dir = R.tmpdir() end)
  after_each(function()
    R.rmdir(dir)
    reg["outcrop.outdir"], reg["outcrop.sandbox"] = nil, nil
  end)

  it("writes binary PLY that reads back to the mesh", function()
    local path = dir .. "/m.ply"
    assert.is_true(m:write(path))
    local ply = read_ply(read_file(path))
    assert.are.equal(nv, ply.nvertex)
    assert.are.equal(nt, ply.nface)
    assert.is_nil(ply.header:find("property uchar red", 1, true))
    for _, i in ipairs{1, nv // 2, nv} do
      local v = {m:vertex(i)}
      local p = ply.verts[i]
      assert.are.same(v, {p.x, p.y, p.z, p.nx, p.ny, p.nz})
    end
    for _, t in ipairs{1, nt} do
      local a, b, c = m:triangle(t)
      assert.are.same({a - 1, b - 1, c - 1}, ply.faces[t])
    end
  end)

  it("writes OBJ with one v line per vertex and one f line per triangle", function()
    local path = dir .. "/m.obj"
    assert.is_true(m:write(path))
    local data = read_file(path)
    local v, vn, f = 0, 0, 0
    for line in data:gmatch("[^\n]+") do
      if line:sub(1, 2) == "v " then v = v + 1 end
      if line:sub(1, 3) == "vn " then vn = vn + 1 end
      if line:sub(1, 2) == "f " then f = f + 1 end
    end
    assert.are.same({nv, nv, nt}, {v, vn, f})
    local x, y, z = data:match("\nv (%S+) (%S+) (%S+)\n")
    local v1 = {m:vertex(1)}
    R.close(tonumber(x), v1[1], 1e-6)
    R.close(tonumber(y), v1[2], 1e-6)
    R.close(tonumber(z), v1[3], 1e-6)
  end)

  it("writes glTF binary", function()
    local path = dir .. "/m.glb"
    assert.is_true(m:write(path))
    local data = read_file(path)
    local magic, version, length, jlen, jtype = string.unpack("<c4I4I4I4c4", data)
    assert.are.equal("glTF", magic)
    assert.are.equal(2, version)
    assert.are.equal(#data, length)
    assert.are.equal("JSON", jtype)
    local json = data:sub(21, 20 + jlen)
    assert.truthy(json:find('"POSITION"', 1, true))
    assert.truthy(json:find('"count":' .. nv, 1, true))
    assert.falsy(json:find('"COLOR_0"', 1, true))
  end)

  it("picks the format from the extension in any case, and refuses others", function()
    assert.is_true(m:write(dir .. "/UP.PLY"))
    assert.are.equal("ply\n", read_file(dir .. "/UP.PLY"):sub(1, 4))
    check(function() m:write(dir .. "/m.stl") end, "mesh:write", "unknown mesh format")
    assert.are.same({"UP.PLY"}, listdir(dir))
  end)

  it("returns nil and a message for an unwritable path, leaving no file", function()
    local ok, msg = m:write("/proc/outcrop-no-such-dir/x.ply")
    assert.is_nil(ok)
    assert.are.equal("string", type(msg))
    assert.is_true(#msg > 0)
    local f = io.open(dir .. "/a-file", "w"); f:close()
    for _, ext in ipairs{"ply", "obj", "glb"} do
      ok, msg = m:write(dir .. "/a-file/x." .. ext)
      assert.is_nil(ok)
      assert.is_true(#msg > 0)
    end
    assert.are.same({"a-file"}, listdir(dir))
  end)

  it("checks its arguments", function()
    check(function() m:write(5) end, "mesh:write", "the path must be a string (got 5)")
    check(function() m:write() end, "mesh:write", "the path must be a string (got no value)")
    check(function() m:write(dir .. "/a.ply", {colour = 1}) end, "mesh:write", "unknown field 'colour'", "did you mean 'colors'?")
    check(function() m:write(dir .. "/a.ply", 5) end, "mesh:write", "expected a table of named fields (got 5)")
    check(function() m:write(dir .. "/a.ply", {}, 1) end, "mesh:write", "too many arguments")
    check(function() m:write(dir .. "/a.ply", {colors = true}) end, "mesh:write", "'colors' must be a function or a table")
    assert.are.same({}, listdir(dir))
  end)

  it("puts relative paths in the output folder, inside the sandbox", function()
    reg["outcrop.outdir"] = dir .. "/out"
    reg["outcrop.sandbox"] = true
    assert.is_true(m:write("sub/m.glb"))
    assert.are.equal("glTF", read_file(dir .. "/out/sub/m.glb"):sub(1, 4))
    check(function() m:write("../escape.ply") end, "mesh:write", "outside the output folder")
    check(function() m:write("/tmp/escape.ply") end, "mesh:write", "outside the output folder")
    assert.is_nil(read_file(dir .. "/escape.ply"))
  end)
end)

describe("colours", function()
  local dir
  before_each(function() dir = R.tmpdir() end)
  after_each(function() R.rmdir(dir) end)

  local function rgb_of(ply, i)
    local v = ply.verts[i]
    return {v.red, v.green, v.blue}
  end

  it("come from a function of position and normal, called once per vertex in order", function()
    local m = oc.polygonize(ball, {cell = 0.4})
    local nv = m:counts()
    local calls = {}
    local function paint(x, y, z, nx, ny, nz)
      calls[#calls + 1] = {x, y, z, nx, ny, nz}
      return z > C[3] and 1 or 0, 0.5, (nz + 1) / 2
    end
    assert.is_true(m:write(dir .. "/c.ply", {colors = paint}))
    assert.are.equal(nv, #calls)
    for _, i in ipairs{1, 2, nv} do assert.are.same({m:vertex(i)}, calls[i]) end
    local ply = read_ply(read_file(dir .. "/c.ply"))
    assert.truthy(ply.header:find("property uchar red\nproperty uchar green\nproperty uchar blue\n", 1, true))
    for i = 1, nv do
      local v = calls[i]
      local c = rgb_of(ply, i)
      assert.are.equal(v[3] > C[3] and 255 or 0, c[1])
      assert.are.equal(188, c[2]) -- linear 0.5 is sRGB 0.7354
      assert.is_true(math.abs(c[3] - srgb255((v[6] + 1) / 2)) <= 0.51)
    end
  end)

  it("stay with the mesh: later PLY and glTF writes carry them, OBJ ignores them", function()
    local m = oc.polygonize(ball, {cell = 0.4})
    assert.is_true(m:write(dir .. "/a.ply", {colors = function() return 0, 1, 0 end}))
    assert.is_true(m:write(dir .. "/b.ply"))
    local ply = read_ply(read_file(dir .. "/b.ply"))
    assert.are.same({0, 255, 0}, rgb_of(ply, 1))
    assert.is_true(m:write(dir .. "/b.glb"))
    assert.truthy(read_file(dir .. "/b.glb"):find('"COLOR_0"', 1, true))
    assert.is_true(m:write(dir .. "/b.obj"))
    assert.are.equal("v ", read_file(dir .. "/b.obj"):match("\n(v )"))
    -- a later colouring replaces them
    assert.is_true(m:write(dir .. "/c.ply", {colors = function() return 0, 0, 1 end}))
    assert.are.same({0, 0, 255}, rgb_of(read_ply(read_file(dir .. "/c.ply")), 1))
  end)

  it("come from a field through a palette", function()
    local geo = oc.point{center = {C[1], C[2], C[3] + 2}, radius = 4}
    local pal = {{0, {0, 0, 1}}, {0.5, {0, 1, 0}}, {1, {1, 0, 0}}}
    local m = oc.polygonize(ball, {cell = 0.4, colors = {field = geo, palette = pal}})
    assert.is_true(m:write(dir .. "/p.ply"))
    local ply = read_ply(read_file(dir .. "/p.ply"))
    local seen_lo, seen_hi = false, false
    for i = 1, ply.nvertex do
      local v = {m:vertex(i)}
      local f = geo:eval(v[1], v[2], v[3])
      local want
      if f < 0.5 then
        local t = f / 0.5
        want = {0, t, 1 - t}
        seen_lo = true
      else
        local t = math.min(1, (f - 0.5) / 0.5)
        want = {t, 1 - t, 0}
        seen_hi = true
      end
      local c = rgb_of(ply, i)
      for k = 1, 3 do
        local w = srgb255(want[k])
        assert.is_true(math.abs(c[k] - w) <= 0.51, string.format("vertex %d: %s vs %s", i, c[k], w))
      end
    end
    assert.is_true(seen_lo and seen_hi) -- both palette segments in use
  end)

  it("clamp at the palette's ends", function()
    local m = oc.polygonize(ball, {cell = 0.5})
    assert.is_true(m:write(dir .. "/k.ply", {colors = {field = ball, palette = {{2, {0.2, 0.4, 0.6}}, {3, {1, 1, 1}}}}}))
    local ply = read_ply(read_file(dir .. "/k.ply"))
    -- linear 0.2, 0.4, 0.6 are sRGB 124, 170, 203 (not 51, 102, 153)
    for i = 1, ply.nvertex do assert.are.same({124, 170, 203}, rgb_of(ply, i)) end
  end)

  it("propagate an error raised in the function, with its line, and leave no file", function()
    local m = oc.polygonize(ball, {cell = 0.5})
    local function bad() error("paint failed") end
    local line = debug.getinfo(bad, "S").linedefined
    local ok, err = pcall(m.write, m, dir .. "/e.ply", {colors = bad})
    local want = F .. ":" .. line .. ": paint failed"
    assert.is_false(ok)
    assert.are.equal(want, err:sub(-#want)) -- busted may prefix "./"
    assert.is_nil(err:find("mesh:write", 1, true)) -- passed through as raised
    ok, err = pcall(oc.polygonize, ball, {cell = 0.5, colors = bad})
    assert.is_false(ok)
    assert.are.equal(want, err:sub(-#want))
    local obj = setmetatable({}, {})
    ok, err = pcall(m.write, m, dir .. "/e.ply", {colors = function() error(obj) end})
    assert.is_false(ok)
    assert.are.equal(obj, err) -- error values pass through untouched
    assert.are.same({}, listdir(dir))
  end)

  it("must be three numbers in [0, 1]", function()
    local m = oc.polygonize(ball, {cell = 0.5})
    local W = "mesh:write"
    local path = dir .. "/n.ply"
    check(function() m:write(path, {colors = function() return 1, "0", 0 end}) end, W, "the colors function must return r, g, b in [0, 1] (got g = string at vertex 1)")
    check(function() m:write(path, {colors = function() return 1, 1 end}) end, W, "(got b = nil at vertex 1)")
    check(function() m:write(path, {colors = function() end}) end, W, "(got r = nil at vertex 1)")
    check(function() m:write(path, {colors = function() return 255, 0, 0 end}) end, W, "(got r = 255 at vertex 1)")
    check(function() m:write(path, {colors = function() return 0, 0 / 0, 0 end}) end, W, "g = ")
    local n = 0
    check(function() m:write(path, {colors = function() n = n + 1; return n < 5 and 0 or -1, 0, 0 end}) end, W, "(got r = -1 at vertex 5)")
    check(function() oc.polygonize(ball, {cell = 0.5, colors = function() return {} end}) end, "outcrop.polygonize", "(got r = table at vertex 1)")
    assert.are.same({}, listdir(dir))
  end)

  it("survive a function that closes the mesh it colours", function()
    -- the write pins the mesh: the close takes effect once it is over
    local m = oc.polygonize(ball, {cell = 0.5})
    local nv = m:counts()
    local function closer() do local c <close> = m end; return 0, 0, 0 end
    assert.is_true(m:write(dir .. "/z.ply", {colors = closer}))
    assert.are.equal("outcrop.mesh: (closed)", tostring(m))
    assert.are.same({"z.ply"}, listdir(dir))
    local head = read_file(dir .. "/z.ply"):match("element vertex (%d+)")
    assert.are.equal(nv, tonumber(head))
  end)

  it("may be a field compiled at outcrop.threshold", function()
    -- a difference evaluates min(fa, 2T - fb): its colours follow T
    local geo = oc.point{center = C, radius = 10} - oc.point{center = C, radius = 10}
    local m = oc.polygonize(ball, {cell = 0.5})
    local pal = {{0, {0, 0, 0}}, {1, {1, 1, 1}}}
    oc.threshold = 0.7
    local ok = m:write(dir .. "/t.ply", {colors = {field = geo, palette = pal}})
    oc.threshold = 0.5
    assert.is_true(ok)
    local ply = read_ply(read_file(dir .. "/t.ply"))
    local v = {m:vertex(1)}
    local fa = oc.point{center = C, radius = 10}:eval(v[1], v[2], v[3])
    local want = math.min(fa, 1.4 - fa)
    assert.is_true(math.abs(rgb_of(ply, 1)[1] - srgb255(want)) <= 0.51)
  end)
end)

describe("components", function()
  local dir
  before_each(function() dir = R.tmpdir() end)
  after_each(function()
    R.rmdir(dir)
    reg["outcrop.params"], reg["outcrop.seed"], reg["outcrop.scene"] = nil, nil, nil
  end)

  -- Two separate balls of radius 1 and 0.5 (iso radii 0.45 and 0.23).
  local two = oc.union{oc.point{center = {-1.5, 0, 0}, radius = 1},
                       oc.point{center = {1.5, 0, 0}, radius = 0.5}}
  local box = {-2.6, -1.1, -1.1, 2.6, 1.1, 1.1}

  it("counts the vertices of each connected component, by lowest vertex", function()
    local m = oc.polygonize(two, {box = box, cell = 0.05})
    local c = m:components()
    assert.are.equal(2, #c)
    assert.are.equal(m:counts(), c[1] + c[2])
    local left = 0
    for i = 1, m:counts() do if m:vertex(i) < 0 then left = left + 1 end end
    local first_left = m:vertex(1) < 0
    assert.are.equal(first_left and left or m:counts() - left, c[1])
    assert.are.equal(math.type(c[1]), "integer")
    local big, small = math.max(c[1], c[2]), math.min(c[1], c[2])
    assert.is_true(small * 3 < big and small * 6 > big)
    local one = oc.polygonize(ball, {cell = 0.5})
    assert.are.same({(one:counts())}, one:components())
    assert.are.same({}, oc.polygonize(oc.point{center = {0, 0, 0}, radius = 1}, {box = {5, 5, 5, 6, 6, 6}}):components())
  end)

  it("min_component drops the small ones, with the same bytes for 1 and 2 threads #slowgc", function()
    local all = oc.polygonize(two, {box = box, cell = 0.05})
    local c = all:components()
    local big, small = math.max(c[1], c[2]), math.min(c[1], c[2])
    for _, k in ipairs{0, 1, small} do
      assert.are.same(c, oc.polygonize(two, {box = box, cell = 0.05, min_component = k}):components())
    end
    local m = oc.polygonize(two, {box = box, cell = 0.05, min_component = small + 1})
    assert.are.same({big}, m:components())
    for i = 1, m:counts() do assert.is_true(m:vertex(i) < 0) end
    local nt = select(2, m:counts())
    for t = 1, nt do
      local a, b, cc = m:triangle(t)
      assert.is_true(a <= big and b <= big and cc <= big)
    end
    assert.are.same({0, 0}, {oc.polygonize(two, {box = box, cell = 0.05, min_component = big + 1}):counts()})
    -- the interpreter's determinism: a child process per thread count
    local build = os.getenv("OUTCROP_TEST_BUILD")
    local script = dir .. "/t.lua"
    local f = assert(io.open(script, "w"))
    f:write(string.format([[
local oc = require "outcrop"
local two = oc.union{oc.point{center = {-1.5, 0, 0}, radius = 1},
                     oc.point{center = {1.5, 0, 0}, radius = 0.5}}
local m = oc.polygonize(two, {box = {-2.6, -1.1, -1.1, 2.6, 1.1, 1.1}, cell = 0.05, min_component = %d})
assert(m:write(arg[1] .. ".ply")); assert(m:write(arg[1] .. ".glb"))
]], small + 1))
    f:close()
    for t = 1, 2 do
      assert.is_true(os.execute(string.format("cd '%s' && OMP_NUM_THREADS=%d LUA_CPATH='%s/?.so;;' lua5.4 t.lua t%d",
        dir, t, build, t)))
    end
    for _, ext in ipairs{".ply", ".glb"} do
      local a, b = read_file(dir .. "/t1" .. ext), read_file(dir .. "/t2" .. ext)
      assert.truthy(a)
      assert.are.equal(a, b)
    end
  end)

  it("checks min_component and the arguments of components", function()
    local P = "outcrop.polygonize"
    check(function() oc.polygonize(ball, {min_component = -1}) end, P, "'min_component' must be an integer in 0..")
    check(function() oc.polygonize(ball, {min_component = 2.5}) end, P, "'min_component'", "(got 2.5)")
    check(function() oc.polygonize(ball, {min_component = "10"}) end, P, "'min_component'", "(got string)")
    check(function() oc.polygonize(ball, {min_comp = 3}) end, P, "unknown field 'min_comp'")
    local m = oc.polygonize(ball, {cell = 0.5})
    check(function() m:components(1) end, "mesh:components", "too many arguments")
  end)

  it("mesh files carry the provenance images get, in every format", function()
    reg["outcrop.scene"] = 'scenes/a "b"\nc.lua'
    reg["outcrop.seed"] = 42
    reg["outcrop.params"] = {height = "3", name = 'x "y"\nz'}
    local m = oc.polygonize(ball, {cell = 0.5})
    for _, ext in ipairs{".ply", ".obj", ".glb"} do assert.is_true(m:write(dir .. "/p" .. ext)) end
    local ply = read_file(dir .. "/p.ply")
    local head = ply:sub(1, select(2, ply:find("end_header\n", 1, true)))
    assert.truthy(head:find('\ncomment outcrop:scene="scenes/a \\"b\\"\\nc.lua"\n', 1, true), head)
    assert.truthy(head:find("\ncomment outcrop:seed=42\n", 1, true), head)
    assert.truthy(head:find("\ncomment outcrop:version=" .. oc.version .. "\n", 1, true), head)
    assert.truthy(head:find('\ncomment outcrop:params="height=3 \\"name=x \\\\\\"y\\\\\\"\\\\nz\\""\n', 1, true), head)
    for line in head:gmatch("[^\n]+") do
      assert.is_truthy(line:match("^comment ") or line:match("^ply$") or line:match("^format ")
        or line:match("^element ") or line:match("^property ") or line:match("^end_header$"), line)
    end
    local obj = read_file(dir .. "/p.obj")
    assert.truthy(obj:find("\n# outcrop:seed=42\n", 1, true))
    assert.truthy(obj:find('\n# outcrop:scene="scenes/a \\"b\\"\\nc.lua"\n', 1, true))
    local glb = read_file(dir .. "/p.glb")
    local jlen = string.unpack("<I4", glb, 13)
    local json = glb:sub(21, 20 + jlen)
    assert.truthy(json:find('"extras":{', 1, true), json)
    assert.truthy(json:find('"outcrop:scene":"scenes/a \\"b\\"\\nc.lua"', 1, true), json)
    assert.truthy(json:find('"outcrop:seed":"42"', 1, true), json)
    assert.truthy(json:find('"outcrop:version":"' .. oc.version .. '"', 1, true), json)
    -- the GLB is otherwise unchanged by provenance: same bytes after the JSON
    reg["outcrop.seed"] = 7
    assert.is_true(m:write(dir .. "/q.glb"))
    local glb2 = read_file(dir .. "/q.glb")
    assert.truthy(glb2:find('"outcrop:seed":"7"', 1, true))
    assert.are.equal(glb:sub(21 + jlen), glb2:sub(21 + string.unpack("<I4", glb2, 13)))
  end)
end)

describe("progress", function()
  -- A child lua5.4 meshes for about a second; `script` gives it a terminal.
  local build = os.getenv("OUTCROP_TEST_BUILD")
  local has_script = os.execute("command -v script >/dev/null 2>&1")

  local function run(shell_redirect)
    local dir = R.tmpdir()
    local f = assert(io.open(dir .. "/p.lua", "w"))
    f:write([[
local oc = require "outcrop"
local m = oc.polygonize(oc.point{center = {0, 0, 0}, radius = 2}, {cell = 0.008, full_grid = true})
io.stderr:write("done ", m:counts(), "\n")
]])
    f:close()
    local cmd = string.format("LUA_CPATH='%s/?.so;;' lua5.4 '%s/p.lua'", build, dir)
    local p = io.popen(shell_redirect(cmd, dir))
    local out = p:read("a")
    p:close()
    R.rmdir(dir)
    return out
  end

  it("is a line on stderr when it is a terminal, cleared at the end #slowgc", function()
    if not (build and has_script) then pending("needs OUTCROP_TEST_BUILD and script(1)") return end
    local out = run(function(cmd) return "script -qec \"" .. cmd .. "\" /dev/null" end)
    assert.truthy(out:find("\routcrop.polygonize: +%d+ %%"), out)
    assert.truthy(out:find("\routcrop.polygonize: 100 %%"), out)
    assert.truthy(out:find("\r +\rdone %d+"), out) -- cleared before the next output
  end)

  it("is silent when stderr is not a terminal #slowgc", function()
    if not build then pending("needs OUTCROP_TEST_BUILD") return end
    local out = run(function(cmd) return cmd .. " 2>&1" end)
    assert.truthy(out:match("^done %d+\n$"), out)
  end)
end)

describe("mesh lifetimes", function()
  after_each(function()
    collectgarbage("incremental", 200, 100)
    collectgarbage("restart")
  end)

  it("survive an eager collector (setpause 0)", function()
    collectgarbage("setpause", 0)
    collectgarbage("setstepmul", 1000)
    local keep = {}
    local dir = R.tmpdir()
    for i = 1, 40 do
      -- the node is garbage as soon as the mesh exists
      local m = oc.polygonize(oc.point{center = {i, 0, 0}, radius = 1 + i % 3 * 0.25}, {cell = 0.25})
      collectgarbage()
      local nv, nt = m:counts()
      assert.are.equal(2 * (nv - 2), nt)
      local x = m:vertex(nv)
      assert.is_true(math.abs(x - i) < 2)
      local geo = oc.point{center = {i, 0, 0}, radius = 3}
      assert.is_true(m:write(dir .. "/g.ply", {colors = {field = geo, palette = {{0, {0, 0, 0}}, {1, {1, 1, 1}}}}}))
      geo = nil
      assert.is_true(m:write(dir .. "/g.glb", {colors = function(px) collectgarbage("step"); return 0, 0, px > i and 1 or 0 end}))
      keep[i % 4] = m
      if i % 7 == 0 then
        local closed <close> = m
      end
    end
    keep = nil
    collectgarbage()
    collectgarbage()
    R.rmdir(dir)
  end)

  it("leave no mesh behind when an error is raised", function()
    collectgarbage("setpause", 0)
    for _ = 1, 50 do
      pcall(oc.polygonize, ball, {cell = 0.5, colors = function() error("x") end})
      pcall(oc.polygonize, ball, {cell = 0.5, colors = {field = ball, palette = {{1, {0, 0, 0}}, {0, {0, 0, 0}}}}})
    end
    collectgarbage()
  end)
end)
