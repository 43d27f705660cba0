// The scenes shipped in scenarios/ (subdirectories included), for data-driven GUI tests: every
// .yaml file but the subsystem definitions, which scenes include and which are not scenes.
#pragma once

#include <QDir>
#include <QDirIterator>
#include <QFileInfo>
#include <QStringList>

namespace dydp::gui::testing {

inline QStringList shipped_scenes() {
  QStringList paths;
  QDirIterator it(DYDP_SCENARIOS_DIR, {"*.yaml"}, QDir::Files, QDirIterator::Subdirectories);
  while (it.hasNext()) {
    const QString path = it.next();
    if (QFileInfo(path).dir().dirName() != "subsystems") paths << path;
  }
  return paths;
}

/// The test row's name: the scene's path under scenarios/.
inline QByteArray scene_row_name(const QString& path) {
  return QDir(DYDP_SCENARIOS_DIR).relativeFilePath(path).toUtf8();
}

}  // namespace dydp::gui::testing
