-- blocks_spec.lua — outcrop.blocks.tile (Paris et al. 2020, section 4):
-- statistics, determinism by seed, blocks as nodes (exact 0 outside their
-- bounds, above T inside, Lipschitz bound 1), meshing a block (closed,
-- genus 0) and a whole tile, and every error with its script line.
local oc = require "outcrop"
local R = require "helpers.ref"

local F = "blocks_spec.lua"
local function check(f, fname, ...) return R.check_error(f, F, fname, ...) end
local B = oc.blocks

-- a small tile: 8 m, r = 0.5 (about 3 000 points), fast
local function small(t)
  t = t or {}
  t.size, t.radius = t.size or 8, t.radius or 0.5
  t.disc_radius = t.disc_radius or {2, 3}
  t.spacing = t.spacing or 1
  return B.tile(t)
end

describe("outcrop.blocks.tile", function()
  it("reports Table 1's statistics fields", function()
    local t = small{type = "rhombohedral", seed = 4}
    local s = t:stats()
    assert.are.equal(24, s.fractures) -- Table 1's #D for rhombohedral
    -- maximal Poisson set: 0.73 points per r^3
    local expect = 0.7336 * (8 / 0.5) ^ 3
    assert.is_true(math.abs(s.points - expect) < 0.05 * expect, s.points)
    assert.are.equal(s.blocks, t:count())
    R.close(s.points_per_block * s.blocks, s.points, 1e-6)
    assert.is_true(s.seconds >= 0 and s.seconds < 60)
    assert.is_true(s.cut > 0 and s.cut < s.edges)
    assert.truthy(tostring(t):find("blocks", 1, true))
  end)

  it("uses each type's default count of discs", function()
    local want = {equidimensional = 15, polyhedral = 44, tabular = 30}
    for ty, n in pairs(want) do
      assert.are.equal(n, small{type = ty, seed = 2}:stats().fractures)
    end
    assert.are.equal(7, small{fractures = 7}:stats().fractures)
    assert.are.equal(16, small{discs = {{center = {4, 4, 4}, normal = {0, 0, 1}, radius = 9}}}:stats().fractures)
  end)

  it("is deterministic by seed", function()
    local a, b, c = small{seed = 9}, small{seed = 9}, small{seed = 10}
    local na, nb, nc = a:node(), b:node(), c:node()
    local same, differ = true, false
    for i = 0, 200 do
      local p = {(i * 0.37) % 8, (i * 0.71) % 8, (i * 0.13) % 8}
      same = same and na:eval(p) == nb:eval(p)
      differ = differ or na:eval(p) ~= nc:eval(p)
    end
    assert.is_true(same)
    assert.is_true(differ)
  end)
end)

describe("tile:block", function()
  local t = small{type = "polyhedral", seed = 3}

  it("is 0 outside its bounds, above T somewhere inside, 1-Lipschitz", function()
    local n = t:block(1)
    assert.are.equal("block", n:kind())
    local x0, y0, z0, x1, y1, z1 = n:bounds()
    assert.is_true(x0 < x1 and y0 < y1 and z0 < z1)
    R.close(n:lipschitz(), 1, 1e-9)
    assert.are.equal(0, n:eval{x0 - 0.01, y0, z0})
    assert.are.equal(0, n:eval{x1 + 1, (y0 + y1) / 2, (z0 + z1) / 2})
    local top = 0
    for i = 0, 10 do
      for j = 0, 10 do
        for k = 0, 10 do
          local p = {x0 + (x1 - x0) * i / 10, y0 + (y1 - y0) * j / 10,
                     z0 + (z1 - z0) * k / 10}
          top = math.max(top, n:eval(p))
        end
      end
    end
    assert.is_true(top > 0.5)
  end)

  it("meshes closed and of genus 0", function()
    local m = oc.polygonize(t:block(2), {cell = 0.1})
    local nv, nt = m:counts()
    assert.is_true(nt > 50)
    assert.are.equal(2 * (nv - 2), nt)
  end)

  it("meshes the whole tile with outcrop.polygonize", function()
    local m = oc.polygonize(t:node(), {box = {0, 0, 0, 8, 8, 8}, cell = 0.25})
    local nv, nt = m:counts()
    assert.is_true(nv > 1000 and nt > 1000)
  end)

  it("refuses an index out of range", function()
    check(function() t:block(100000) end, "tile:block", "out of range 1 ..")
    check(function() t:block(0) end, "tile:block", "out of range")
  end)
end)

describe("outcrop.blocks.tile errors", function()
  it("names the field", function()
    check(function() B.tile{radius = 30} end, "outcrop.blocks.tile", "'radius' 30 is too large for a tile of 'size' 20")
    check(function() B.tile{fractures = 0} end, "outcrop.blocks.tile", "'fractures' must be in 1 ..")
    check(function() B.tile{size = 8, radius = 0.5, discs = {{center = {1, 2, 3}, normal = {0, 0, 0}, radius = 2}}} end, "outcrop.blocks.tile", "'discs[1].normal' must be finite and non-zero")
    check(function() B.tile{discs = {{center = {1, 2, 3}, normal = {0, 0, 1}}}} end, "outcrop.blocks.tile", "discs[1].radius")
    check(function() B.tile{type = "cubic"} end, "outcrop.blocks.tile", "'type' must be one of", "\"tabular\"")
    check(function() B.tile{sise = 20} end, "outcrop.blocks.tile", "unknown field 'sise'")
    check(function() B.tile{disc_radius = {3, 1}} end, "outcrop.blocks.tile", "'disc_radius' must be {lo, hi}")
    check(function() B.tile{size = 8, radius = 0.5, fractures = 5000} end, "outcrop.blocks.tile", "could place only")
  end)

  it("refuses discs that would wrap the periodic tile without end", function()
    -- (a fuzzer's disc radius of math.maxinteger made 3.7e17 images a side)
    check(function() B.tile{size = 6, radius = 0.75, disc_radius = {6, math.maxinteger}} end,
      "outcrop.blocks.tile", "'disc_radius' 9.22337e+18 is too large for a tile of 'size' 6 (at most 16 sizes)")
    check(function() B.tile{size = 8, radius = 0.5, discs = {{center = {1, 2, 3}, normal = {0, 0, 1}, radius = 1e9}}} end,
      "outcrop.blocks.tile", "'discs[1].radius' 1e+09 is too large")
    -- each within 16 sizes, but 500 of them make 1.7 million images
    check(function() B.tile{disc_radius = {300, 320}, fractures = 500} end,
      "outcrop.blocks.tile", "periodic images in the tile (at most 1e+06)")
    -- 16 sizes still builds
    local big = B.tile{size = 8, radius = 0.5, disc_radius = {100, 128}, fractures = 2, spacing = 1}
    assert.is_true(big:stats().blocks >= 1)
  end)
end)

describe("outcrop.blocks.replicate", function()
  -- a 40 x 40 x 20 m box: vertical walls, a flat top
  local ter = oc.box{min = {0, 0, 0}, max = {40, 40, 20}, falloff = 1}
  local t = small{seed = 4}

  it("puts blocks on steep walls only and counts the instances", function()
    local r = B.replicate(ter, {tiles = {{tile = t}}, slope = 0.5})
    assert.are.equal("replicate", r:kind())
    local n = r:stats().instances
    assert.is_true(n > 20, n)
    assert.is_nil(ter:stats().instances)
    local top, wall = 0, 0
    for i = 0, 40 do
      for j = 0, 40 do
        local u, v = 10 + i / 2, 10 + j / 2
        top = math.max(top, r:eval{u, v, 20.4} - ter:eval{u, v, 20.4})
        local y, z = 5 + i * 0.75, 2 + j * 0.4
        wall = math.max(wall, r:eval{-1, y, z} - ter:eval{-1, y, z})
      end
    end
    assert.are.equal(0, top)
    assert.is_true(wall > 0.1, wall)
    -- the same tile gives the same instances
    assert.are.equal(n, B.replicate(ter, {tiles = {{tile = t}}, slope = 0.5}):stats().instances)
  end)

  it("names the field in errors", function()
    check(function() B.replicate(ter, {}) end, "outcrop.blocks.replicate", "'tiles'")
    check(function() B.replicate(ter, {tiles = {{tile = 3}}}) end, "outcrop.blocks.replicate", "'tiles[1].tile' must be a block tile")
    check(function() B.replicate(ter, {tiles = {{tile = t}}, distance = {2, 1}}) end, "outcrop.blocks.replicate", "'distance' must be {va, vb} with va <= vb")
    check(function() B.replicate(ter, {tiles = {{tile = t}}, slope = 0}) end, "outcrop.blocks.replicate", "'slope'")
  end)
end)
