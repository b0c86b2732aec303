-- helpers/files.lua — reading back what the specs write: whole files,
-- folder listings, shell commands, and image metadata through oiiotool.
local M = {}

-- The bytes of a file, or nil when it cannot be opened.
function M.read_file(path)
  local f = io.open(path, "rb")
  if not f then return nil end
  local s = f:read("a")
  f:close()
  return s
end

-- The names in a folder (hidden ones included), sorted.
function M.listdir(dir)
  local p = io.popen("ls -A '" .. dir .. "'")
  local names = {}
  for name in p:lines() do names[#names + 1] = name end
  p:close()
  table.sort(names)
  return names
end

-- A command's standard output and error, together.
function M.sh(cmd)
  local p = assert(io.popen(cmd .. " 2>&1"))
  local out = p:read("a")
  p:close()
  return out
end

-- oiiotool's listing of an image: its attributes (key -> the text between
-- the first and the last double quote), the whole listing, and the
-- channel list.
function M.image_info(path)
  local text = M.sh("oiiotool --info -v '" .. path .. "'")
  local attrs = {}
  for line in text:gmatch("[^\n]+") do
    local k, v = line:match('^%s+([%w:_%.%-]+): "(.*)"$')
    if k then attrs[k] = v end
  end
  return attrs, text, text:match("channel list: ([^\n]*)")
end

return M
