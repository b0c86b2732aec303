-- blocks_authored_spec.lua — outcrop.blocks.tile's `blocks` field
-- (authored blocks: box, points or planes), the prismatic and columnar
-- types, and the memory of a replication node (node:stats().block_bytes).
local oc = require "outcrop"
local R = require "helpers.ref"

local F = "blocks_authored_spec.lua"
local function check(f, fname, ...) return R.check_error(f, F, fname, ...) end
local B = oc.blocks
local T = "outcrop.blocks.tile"

-- a small tile: 8 m, r = 0.5, fast
local function opts(t)
  t.size, t.radius, t.disc_radius, t.spacing = 8, 0.5, {2, 3}, 1
  return t
end
local function small(t) return B.tile(opts(t)) end

describe("authored blocks", function()
  it("keeps a box whole as the last block", function()
    local t = small{seed = 2, blocks = {{box = {2, 2, 2, 5, 4, 3.5}}}}
    local s = t:stats()
    assert.are.equal(1, s.authored)
    local b = t:block(s.blocks)
    assert.is_true(b:eval{3.5, 3, 2.75} > 0.5)
    -- its support: the box grown by the width 0.75
    local x0, y0, z0, x1, y1, z1 = b:bounds()
    R.close(x0, 1.25, 1e-9)
    R.close(z1, 4.25, 1e-9)
    -- no other block reaches into it
    local others = {}
    for i = 1, s.blocks - 1 do others[i] = t:block(i) end
    local u = oc.union(others)
    for i = 0, 20 do
      local p = {2.2 + 2.6 * i / 20, 2.2 + 1.6 * ((i * 7) % 20) / 20, 2.2 + 1.1 * ((i * 3) % 20) / 20}
      assert.is_true(u:eval(p) < 0.5, i)
    end
  end)

  it("are still authored in a tile saved and loaded", function()
    local t = small{seed = 2, type = "columnar", blocks = {{box = {2, 2, 2, 5, 4, 3.5}}}}
    local dir = R.tmpdir()
    assert.is_true(t:save(dir .. "/a.octile"))
    local l = B.load(dir .. "/a.octile")
    local a, b = t:stats(), l:stats()
    assert.are.equal(1, b.authored)
    assert.are.equal(a.blocks, b.blocks)
    local p = {3.5, 3, 2.75}
    assert.are.equal(t:block(a.blocks):eval(p), l:block(b.blocks):eval(p))
    R.rmdir(dir)
  end)

  it("takes points and planes", function()
    local t = small{seed = 2, blocks = {
      {points = {{1, 1, 1}, {3, 1, 1}, {1, 3, 1}, {1, 1, 3}}},
      {planes = {{1, 0, 0, -6}, {-1, 0, 0, 5}, {0, 1, 0, -6}, {0, -1, 0, 5},
                 {0, 0, 1, -6}, {0, 0, -1, 5}}}}}
    local s = t:stats()
    assert.are.equal(2, s.authored)
    assert.is_true(t:block(s.blocks - 1):eval{1.4, 1.4, 1.4} > 0.5)
    assert.is_true(t:block(s.blocks):eval{5.5, 5.5, 5.5} > 0.5)
  end)

  it("names the field in errors", function()
    check(function() B.tile(opts{blocks = {{box = {0, 0, 0, 1, 1, 1}, points = {}}}}) end, T, "'blocks[1]' needs one of 'box', 'points', 'planes' (got 2)")
    check(function() B.tile(opts{blocks = {{box = {0, 0, 0, 1, 1}}}}) end, T, "'blocks[1].box' must be {x0, y0, z0, x1, y1, z1}")
    check(function() B.tile(opts{blocks = {{box = {0, 0, 0, 0, 1, 1}}}}) end, T, "'blocks[1].box' must have min < max")
    check(function() B.tile(opts{blocks = {{points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}}}}}) end, T, "'blocks[1]' is flat")
    check(function() B.tile(opts{blocks = {{planes = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {-1, -1, 0, -1}}}}}) end, T, "'blocks[1].planes' do not bound a block")
    check(function() B.tile(opts{blocks = {{planes = {{1, 0, 0}}}}}) end, T, "'blocks[1].planes[1]' must be {nx, ny, nz, d}")
    check(function() B.tile(opts{blocks = {{box = {0, 0, 0, 7, 1, 1}}}}) end, T, "'blocks[1]' is 7 x 1 x 1: it must be less than")
    check(function() B.tile(opts{blocks = {{sphere = 1}}}) end, T, "blocks[1].sphere")
  end)
end)

describe("prismatic and columnar tiles", function()
  it("have their own default disc counts", function()
    assert.are.equal(12, small{type = "prismatic", seed = 1}:stats().fractures)
    assert.are.equal(12, small{type = "columnar", seed = 1}:stats().fractures)
  end)
end)

describe("node:stats().block_bytes", function()
  it("counts the blocks' fields, the instances and their grid", function()
    local t = small{seed = 4}
    local ter = oc.box{min = {0, 0, 0}, max = {40, 40, 20}, falloff = 1}
    local r = B.replicate(ter, {tiles = {{tile = t}}, slope = 0.5})
    local s = r:stats()
    -- at least 32 bytes a plane for 4 planes a block, and an instance each
    assert.is_true(s.block_bytes > 128 * t:count() + 32 * s.instances, s.block_bytes)
    assert.is_true(s.block_bytes < 4e6, s.block_bytes)
    assert.is_nil(ter:stats().block_bytes)
  end)
end)
